#!/usr/bin/python3
"""Client benchmark: a trajectory loss and its gradient through PyTorch.

L(x) = 1/2 sum_k,v |p_v(q(t_k)) - o_kv|^2 over T frames of 64 knot vertices,
q(t) the ballistic trajectory of diff_rigid_body.trajectory_fitting, dL/dx by
autograd through diff_rigid_body.torch.vertex_positions: a positions call and
a backprop call for all T frames (batched) against 2T calls (per frame).

For T = 100 and T = 1000 it reports the best wall time of loss + gradient
over the repeats, the share of it spent inside the service calls (rospy
serialisation, transport and the node: timed around RigidBodyClient.call) and
in Python (torch, numpy, the client's conversions: the rest), the speed-up
of batched over per-frame calls, and checks that both give the same loss and
gradient bit for bit. Prints a markdown section (and writes it to --output).

Needs a running rigid_body_server on the default scene:
    roslaunch diff_rigid_body server.launch &   bench/client_trajectory.py
"""
import argparse
import platform
import sys
import time

import numpy as np
import rospy
import torch

from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body import torch as drb_torch
from diff_rigid_body import trajectory_fitting

X = np.array([0.2, -0.3, 0.5, 0.0, 0.0, 1.0, 1.5, 0.8, -1.0, 0.5, -0.3, 4.0])  # q0, qdot0
TARGET_SPEEDUP = 20.0  # T = 1000: batched against per-frame


class TimedCalls(object):
    """Accumulates the wall time spent in ``client.call`` (every service call), in
    total (``seconds``) and per service (``by_service``)."""

    def __init__(self, client):
        self.reset()
        call = client.call

        def timed(name, **request):
            start = time.perf_counter()
            try:
                return call(name, **request)
            finally:
                elapsed = time.perf_counter() - start
                self.seconds += elapsed
                self.by_service[name] = self.by_service.get(name, 0.0) + elapsed
                self.count += 1
        client.call = timed

    def reset(self):
        self.seconds, self.count, self.by_service = 0.0, 0, {}


def loss_and_gradient(client, observed, times, vertices, per_frame):
    x = torch.tensor(X + 0.01, dtype=torch.float64, requires_grad=True)
    p = drb_torch.vertex_positions(client, 'knot', trajectory_fitting.trajectory(x, times), vertices, per_frame)
    loss = 0.5 * ((p - observed) ** 2).sum()
    loss.backward()
    return loss.detach().numpy(), x.grad.numpy()


def measure(client, timer, frames, vertices, repeats):
    """{'batched'|'per-frame': (best total [s], call time [s] of that run, calls, loss, gradient)}."""
    times = torch.arange(frames, dtype=torch.float64) / 100.0
    observed = torch.from_numpy(drb_torch.positions_batch(client, 'knot', trajectory_fitting.trajectory(
        X, times.numpy()), vertices).copy())
    rows = {}
    for label, per_frame, count in (('batched', False, repeats), ('per-frame', True, max(1, repeats // 3))):
        best = None
        for _ in range(count):
            timer.reset()
            start = time.perf_counter()
            loss, gradient = loss_and_gradient(client, observed, times, vertices, per_frame)
            total = time.perf_counter() - start
            if best is None or total < best[0]:
                best = (total, timer.seconds, timer.count, loss, gradient, dict(timer.by_service))
        rows[label] = best
    return rows


def report(results, vertices):
    lines = ['## Client (PyTorch) trajectories', '',
             'bench/client_trajectory.py: L = 1/2 sum |p(q(t_k)) - o_k|^2 over T frames of %d knot vertices and '
             'dL/d(q0, qdot0) by autograd through `diff_rigid_body.torch.vertex_positions` (Python client, '
             'persistent connections, node on the same machine; %s, Python %s, torch %s). Best of the repeats; '
             '"in calls" = time inside `RigidBodyClient.call` (rospy serialisation + transport + node), '
             '"Python" = the rest (torch, numpy, request building).' % (
                 len(vertices), platform.machine(), platform.python_version(), torch.__version__), '',
             '| T | calls | wall time | in calls | of which positions | of which backprop | Python | speed-up | '
             'gradient batched == per-frame |',
             '|---|---|---|---|---|---|---|---|---|']
    for frames, rows in results:
        b, s = rows['batched'], rows['per-frame']
        identical = np.array_equal(b[3], s[3]) and np.array_equal(b[4], s[4])
        for label, (total, calls_time, calls, _, _, by_service) in (('batched', b), ('per-frame', s)):
            lines.append('| %d %s | %d | %.4f s | %.0f%% | %.0f%% | %.0f%% | %.0f%% | %s | %s |' % (
                frames, label, calls, total, 100.0 * calls_time / total,
                100.0 * by_service.get('get_vertex_jacobians_compact', 0.0) / total,
                100.0 * by_service.get('backprop', 0.0) / total, 100.0 * (1.0 - calls_time / total),
                '%.1fx' % (s[0] / b[0]) if label == 'batched' else '1x', 'yes' if identical else 'NO'))
    for frames, rows in results:
        if frames == 1000:
            speedup = rows['per-frame'][0] / rows['batched'][0]
            lines += ['', 'Target: T = 1000 batched >= %gx faster than per-frame: %.1fx, %s.' % (
                TARGET_SPEEDUP, speedup, 'met' if speedup >= TARGET_SPEEDUP else 'missed')]
    return '\n'.join(lines) + '\n'


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--server', default='rigid_body_server')
    parser.add_argument('--frames', type=int, nargs='+', default=[100, 1000])
    parser.add_argument('--repeats', type=int, default=9, help='batched repeats (per-frame: a third)')
    parser.add_argument('--output', help='also write the markdown section to this file')
    args = parser.parse_args(rospy.myargv()[1:])
    client = RigidBodyClient(args.server).connect()
    vertices = np.linspace(0, 4095, 64).astype(np.uint32)
    timer = TimedCalls(client)
    loss_and_gradient(client, torch.zeros(3, 64, 3, dtype=torch.float64), torch.zeros(3, dtype=torch.float64),
                      vertices, False)  # warm-up
    results = [(frames, measure(client, timer, frames, vertices, args.repeats)) for frames in args.frames]
    text = report(results, vertices)
    print(text)
    if args.output:
        with open(args.output, 'w') as f:
            f.write(text)
    failures = []
    for frames, rows in results:
        if not (np.array_equal(rows['batched'][4], rows['per-frame'][4]) and
                np.array_equal(rows['batched'][3], rows['per-frame'][3])):
            failures.append('T = %d: batched and per-frame gradients differ' % frames)
        speedup = rows['per-frame'][0] / rows['batched'][0]
        if frames == 1000 and speedup < TARGET_SPEEDUP:
            print('note: T = 1000 speed-up %.1fx is below the target %gx' % (speedup, TARGET_SPEEDUP))
    for failure in failures:
        print('bench: FAILED: %s' % failure)
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
