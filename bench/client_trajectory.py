#!/usr/bin/python3
"""Client benchmark: a trajectory loss and its gradient through PyTorch.

L(x) = 1/2 sum_k,v |p_v(q(t_k)) - o_kv|^2 over T frames of 64 knot vertices,
q(t) the ballistic trajectory of diff_rigid_body_examples.trajectory_fitting, dL/dx by
autograd through diff_rigid_body.torch.vertex_positions: a positions call and
a backprop call for all T frames (batched) against 2T calls (per frame).

For T = 100 and T = 1000 it reports the best wall time of loss + gradient
over the repeats, the share of it spent inside the service calls
(serialisation, transport and the node: timed around RigidBodyClient.call) and
in Python (torch, numpy, the client's conversions: the rest), the speed-up
of batched over per-frame calls, and checks that both give the same loss and
gradient bit for bit, for each client transport asked for (--transports:
'tcpros', the client's own buffer path, and 'rospy', rospy.ServiceProxy with
numpy_msg; the gradients of all must agree bit for bit). With --floor (the node
needs ~benchmark_services) it also times ~echo carrying the bytes of the two
batched calls at T = 1000 through each transport: the transport's floor for
the batched gradient. Prints a markdown section (and writes it to --output).

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
from rospy.numpy_msg import numpy_msg

from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body import torch as drb_torch
from diff_rigid_body_examples import trajectory_fitting
from diff_rigid_body.client_arrays import to_wire
from diff_rigid_body.srv import Echo

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


class EchoClient(RigidBodyClient):
    """The client with the benchmark-only ~echo (~benchmark_services)."""
    SERVICES = dict(RigidBodyClient.SERVICES, echo=Echo)


def echo_floor(server, transport, frames, vertices, repeats):
    """Best wall time [s] of ~echo carrying the bytes of the batched positions call (q up, 3 N
    positions per frame down) and of the batched backprop call (3 N gradients and q up, d = 6 per
    frame down) at T = ``frames``, through ``transport``."""
    client = EchoClient(server, transport=transport)
    calls = [(6 * frames + len(vertices) // 2, 3 * len(vertices) * frames),
             (3 * len(vertices) * frames + 6 * frames + len(vertices) // 2, 6 * frames)]
    total = 0.0
    for up, down in calls:
        message = to_wire(numpy_msg(Echo._request_class)(data=np.zeros(up), response_size=down))
        best = None
        for _ in range(repeats + 1):
            start = time.perf_counter()
            client.send('echo', message)
            elapsed = time.perf_counter() - start
            best = elapsed if best is None else min(best, elapsed)
        total += best
    return total


def table_rows(transport, results):
    rows = []
    for frames, measured in results:
        b, s = measured['batched'], measured['per-frame']
        identical = np.array_equal(b[3], s[3]) and np.array_equal(b[4], s[4])
        for label, (total, calls_time, calls, _, _, by_service) in (('batched', b), ('per-frame', s)):
            rows.append('| %s | %d %s | %d | %.4f s | %.0f%% | %.0f%% | %.0f%% | %.0f%% | %s | %s |' % (
                transport, frames, label, calls, total, 100.0 * calls_time / total,
                100.0 * by_service.get('get_vertex_jacobians_compact', 0.0) / total,
                100.0 * by_service.get('backprop', 0.0) / total, 100.0 * (1.0 - calls_time / total),
                '%.1fx' % (s[0] / b[0]) if label == 'batched' else '1x', 'yes' if identical else 'NO'))
    return rows


def report(results, vertices, floors):
    """``results``: {transport: [(T, rows of measure())]}; ``floors``: {transport: echo floor [s] at T = 1000}."""
    lines = ['## Client (PyTorch) trajectories', '',
             'bench/client_trajectory.py: L = 1/2 sum |p(q(t_k)) - o_k|^2 over T frames of %d knot vertices and '
             'dL/d(q0, qdot0) by autograd through `diff_rigid_body.torch.vertex_positions` (Python client, '
             'persistent connections, node on the same machine; %s, Python %s, torch %s). Best of the repeats; '
             '"in calls" = time inside `RigidBodyClient.call` (serialisation + transport + node), '
             '"Python" = the rest (torch, numpy, request building). Transport `tcpros`: the client\'s buffer path '
             '(`diff_rigid_body.tcpros`); `rospy`: `rospy.ServiceProxy` with `numpy_msg` both ways.' % (
                 len(vertices), platform.machine(), platform.python_version(), torch.__version__), '',
             '| transport | T | calls | wall time | in calls | of which positions | of which backprop | Python | '
             'speed-up | gradient batched == per-frame |',
             '|---|---|---|---|---|---|---|---|---|---|']
    for transport, measured in results.items():
        lines += table_rows(transport, measured)
    if floors:
        lines += ['', 'Floor at T = 1000: ~echo carrying the same bytes as the two batched calls (the transport '
                  'alone, no computation, no torch):', '']
        for transport, floor in floors.items():
            batched = dict(results[transport])[1000]['batched'][0] if transport in results else float('nan')
            lines.append('- `%s`: %.4f s, against %.4f s for the batched loss and gradient' % (transport, floor,
                                                                                              batched))
    for transport, measured in results.items():
        for frames, rows in measured:
            if frames == 1000:
                speedup = rows['per-frame'][0] / rows['batched'][0]
                lines += ['', 'Target (%s): T = 1000 batched >= %gx faster than per-frame: %.1fx, %s.' % (
                    transport, TARGET_SPEEDUP, speedup, 'met' if speedup >= TARGET_SPEEDUP else 'missed')]
    return '\n'.join(lines) + '\n'


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--server', default='rigid_body_server')
    parser.add_argument('--frames', type=int, nargs='+', default=[100, 1000])
    parser.add_argument('--repeats', type=int, default=9, help='batched repeats (per-frame: a third)')
    parser.add_argument('--transports', nargs='+', default=['tcpros'], choices=['tcpros', 'rospy'])
    parser.add_argument('--floor', action='store_true', help='also time ~echo of the same bytes (needs '
                        '~benchmark_services)')
    parser.add_argument('--output', help='also write the markdown section to this file')
    args = parser.parse_args(rospy.myargv()[1:])
    vertices = np.linspace(0, 4095, 64).astype(np.uint32)
    results, floors, gradients = {}, {}, {}
    for transport in args.transports:
        client = RigidBodyClient(args.server, transport=transport).connect()
        timer = TimedCalls(client)
        loss_and_gradient(client, torch.zeros(3, 64, 3, dtype=torch.float64), torch.zeros(3, dtype=torch.float64),
                          vertices, False)  # warm-up
        results[transport] = [(frames, measure(client, timer, frames, vertices, args.repeats))
                              for frames in args.frames]
        gradients[transport] = [rows['batched'][4] for _, rows in results[transport]]
        if args.floor:
            floors[transport] = echo_floor(args.server, transport, 1000, vertices, args.repeats)
    text = report(results, vertices, floors)
    print(text)
    if args.output:
        with open(args.output, 'w') as f:
            f.write(text)
    failures = []
    for transport, measured in results.items():
        for frames, rows in measured:
            if not (np.array_equal(rows['batched'][4], rows['per-frame'][4]) and
                    np.array_equal(rows['batched'][3], rows['per-frame'][3])):
                failures.append('%s, T = %d: batched and per-frame gradients differ' % (transport, frames))
    first = gradients[args.transports[0]]
    for transport, own in gradients.items():
        if any(a.tobytes() != b.tobytes() for a, b in zip(own, first)):
            failures.append('%s and %s give different gradients' % (transport, args.transports[0]))
    for failure in failures:
        print('bench: FAILED: %s' % failure)
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
