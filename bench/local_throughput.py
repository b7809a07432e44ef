#!/usr/bin/python3
"""In process: diff_rigid_body.LocalScene against its C++ core, the node and Dask.

    source $DRB_WORKSPACE/devel/setup.bash && bench/local_throughput.py --out DIR [--quick]

(scripts/bench runs it and bench/report_local.py puts the section "In process" in
docs/benchmarks.md). Writes DIR/local.json with, per measurement, seconds per call (median over
timing windows of the windows' means, and the best window):
  * kernel: LocalScene's calls that drb_bench_local (bench/bench_local.cpp) times in C++ on the
    same inputs: M of the UR5 and of the Panda (K = 1), backprop of the UR5 (K = 1000, 400 vertices);
    also the compiled module's call alone (diff_rigid_body._local, no Python wrapper) and, with
    --bin, the C++ row itself (one drb_bench_local run per window), all taking turns;
  * trajectory: bench/client_trajectory.py's loss and gradient at T = 1000 (batched) through
    diff_rigid_body.torch on a LocalScene, against the same module calls replayed (the core's time);
  * node: the same backprop and trajectory through RigidBodyClient's tcpros buffer transport to a
    rigid_body_server under its own roscore (bench/pool_throughput.py's Graph); answers compared;
  * dask: forward dynamics with derivatives of the floating humanoid (simple_humanoid.urdf with
    floating_base, as local_dask.test), K = 20000, over a distributed.LocalCluster of 1 and of 2
    worker processes (one thread each), checked bit for bit against LocalScene in this process
    (bench/local_dask_throughput.py; calls of 5000 configurations: one call of all K is over the core's answer limit), and
    the same shards computed with their answers left on the workers (no transfer);
  * memory: a K = 100000 batch (M of the UR5; positions of 32 UR5 vertices) in a fresh process:
    RSS before and peak RSS (VmHWM, reset just before the call) after, against the answer's bytes
    (ru_maxrss too, which the load's own peak masks).
Inputs: bench/bench_local.cpp's formulas (exact binary fractions).
"""
import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)
ROBOTS = os.path.join(REPO, 'test/robots/drb_example_robot_data/robots')
UR5 = os.path.join(ROBOTS, 'ur_description/urdf/ur5_robot.urdf')
PANDA = os.path.join(ROBOTS, 'panda_description/urdf/panda.urdf')
HUMANOID = os.path.join(ROBOTS, 'simple_humanoid_description/urdf/simple_humanoid.urdf')
DEMO = os.path.join(REPO, 'urdf/demo_scene.urdf')
PARTS = ('kernel', 'trajectory', 'node', 'memory', 'dask')


def log(text):
    print('[local bench] ' + text, file=sys.stderr, flush=True)


def configurations(K, d, panda=False):
    """q[k, j] = ((7 k + 13 j) mod 41 - 20) / 32; the Panda's finger (j = 7) 1/64 m."""
    k, j = np.meshgrid(np.arange(K), np.arange(d), indexing='ij')
    q = (((7 * k + 13 * j) % 41) - 20.0) / 32.0
    if panda:
        q[:, 7] = 1.0 / 64
    return np.ascontiguousarray(q)


def vertex_gradients(K, N):
    """dL/dp[k, v, c] = ((5 k + 11 v + 3 c) mod 29 - 14) / 16, shape (K, N, 3)."""
    k, v, c = np.meshgrid(np.arange(K), np.arange(N), np.arange(3), indexing='ij')
    return np.ascontiguousarray((((5 * k + 11 * v + 3 * c) % 29) - 14.0) / 16.0)


def selected_vertices(count, N):
    """Vertex i of N: floor(i count / N)."""
    return (np.arange(N, dtype=np.uint64) * count // N).astype(np.uint32)


def warm_up(call, window):
    """Calls ``call()`` for one window and at least 3 calls (a node's service threads fault in
    their malloc arenas' pages on the first large requests)."""
    start = time.perf_counter()
    for count in range(1 << 30):
        if count >= 3 and time.perf_counter() - start >= window:
            break
        call()


def window_mean(call, window):
    """[s] per call of ``call()``, the mean over one window of at least ``window`` seconds."""
    count, start = 0, time.perf_counter()
    while True:
        call()
        count += 1
        elapsed = time.perf_counter() - start
        if elapsed >= window:
            return elapsed / count


def summary(means):
    return {'median': float(np.median(means)), 'best': float(min(means)), 'windows': len(means)}


def timed(call, window, windows):
    """{'median', 'best'}: seconds per call of ``call()``, over ``windows`` windows of at least
    ``window`` seconds each, after a warm-up."""
    return interleaved({'call': call}, window, windows)['call']


def interleaved(calls, window, windows, windowed=None):
    """{name: {'median', 'best'}} for every ``calls[name]()`` (and every ``windowed[name]()``,
    which measures one window itself and returns its seconds per call): the sides take turns,
    one window each, ``windows`` times, so that a slow phase of a shared machine lands on all."""
    for call in calls.values():
        warm_up(call, window)
    sides = {name: (lambda c=call: window_mean(c, window)) for name, call in calls.items()}
    sides.update(windowed or {})
    means = {name: [] for name in sides}
    for _ in range(windows):
        for name, side in sides.items():
            means[name].append(side())
    return {name: summary(values) for name, values in means.items()}


def core_window(binary, row, window):
    """[s] per call of drb_bench_local's row ``row`` over one window (a run of its own: the C++
    core call that LocalScene makes, on the same inputs), or None without the binary."""
    if not binary:
        return None
    text = subprocess.run([binary, '--benchmark_filter=^local/%s$' % row, '--benchmark_min_time=%g' % window,
                           '--benchmark_format=json'], check=True, capture_output=True, text=True).stdout
    run = json.loads(text)['benchmarks'][0]
    return run['real_time'] * {'ns': 1e-9, 'us': 1e-6, 'ms': 1e-3, 's': 1.0}[run['time_unit']]


def ur5_backprop_request(scene, K=1000, N=400):
    bodies = scene.bodies()
    body, d, count = bodies.names[0], int(bodies.dofs[0]), int(bodies.vertex_counts[0])
    return dict(body=body, gradients=vertex_gradients(K, N), q=configurations(K, d),
                vertices=selected_vertices(count, N))


def measure_kernel_side(args):
    """LocalScene's per-call times for drb_bench_local's rows, the module call alone and (with
    --bin) the row's C++ core call, taking turns."""
    from diff_rigid_body import LocalScene
    out = {}

    def core(row):
        return {'core': lambda: core_window(args.bin, row, args.window)} if args.bin else None
    for robot, urdf in (('ur5', UR5), ('panda', PANDA)):
        scene = LocalScene(urdf_path=urdf)
        q = configurations(1, int(sum(scene.bodies().dofs)), robot == 'panda')
        flat = q.reshape(-1)  # the module takes flat fields, as the wrapper passes them
        row = '%s/mass_matrix_K1' % robot
        out[row] = interleaved(dict(local=lambda: scene.mass_matrix(q=q),
                                    module=lambda: scene._scene.get_mass_matrix(bodies=[], q=flat)),
                               args.window, args.windows, core(row))
    scene = LocalScene(urdf_path=UR5)
    r = ur5_backprop_request(scene)
    raw = dict(body=r['body'], vertices=r['vertices'], gradients=r['gradients'].ravel(), q=r['q'].ravel())
    row = 'ur5/backprop_K1000_N400'
    out[row] = interleaved(dict(local=lambda: scene.backprop(**r), module=lambda: scene._scene.backprop(**raw)),
                           args.window, args.windows, core(row))
    out[row]['request_bytes'] = int(r['gradients'].nbytes + r['q'].nbytes + r['vertices'].nbytes)
    return out


class Recorder(object):
    """Records every (service, request) a LocalScene's ``call`` makes while ``recording`` (an
    instance attribute over the class's method: ``del scene.call`` ends it); ``replay()`` sends
    them to the compiled module directly (the core's time for the same calls)."""

    def __init__(self, scene):
        self.scene, self.calls, self.recording = scene, [], False
        original = scene.call

        def call(name, **request):
            if self.recording:
                self.calls.append((name, request))
            return original(name, **request)
        scene.call = call

    def replay(self):
        for name, request in self.calls:
            getattr(self.scene._scene, name)(**request)


def trajectory_setup(client, frames=1000):
    """bench/client_trajectory.py's inputs at T = ``frames``: (observed, times, vertices)."""
    import torch
    import client_trajectory as ct
    from diff_rigid_body import torch as drb_torch
    from diff_rigid_body_examples import trajectory_fitting
    vertices = np.linspace(0, 4095, 64).astype(np.uint32)
    times = torch.arange(frames, dtype=torch.float64) / 100.0
    observed = torch.from_numpy(drb_torch.positions_batch(client, 'knot', trajectory_fitting.trajectory(
        ct.X, times.numpy()), vertices).copy())
    return observed, times, vertices


def trajectory_gradient(client, setup):
    import client_trajectory as ct
    return ct.loss_and_gradient(client, setup[0], setup[1], setup[2], False)


def measure_trajectory(args):
    """Loss + gradient at T = 1000 on a LocalScene, and the same module calls replayed."""
    from diff_rigid_body import LocalScene
    scene = LocalScene(urdf_path=DEMO)
    setup = trajectory_setup(scene)
    recorder = Recorder(scene)
    trajectory_gradient(scene, setup)  # the scene's dofs are asked once (get_bodies), then cached
    recorder.recording = True
    loss, gradient = trajectory_gradient(scene, setup)
    del scene.call  # the class's own call again, unwrapped, for the timing
    result = interleaved(dict(local=lambda: trajectory_gradient(scene, setup), kernels=recorder.replay),
                         args.window, args.windows)
    result['calls'] = [name for name, _ in recorder.calls]
    result['in_calls'] = seconds_in_calls(scene, setup, args.window)
    return result, (loss, gradient)


def seconds_in_calls(scene, setup, window):
    """[s] per loss + gradient spent inside LocalScene.call (the module's calls and their
    wrapping), over a window; the rest is torch and the client's Python."""
    import client_trajectory as ct
    timer = ct.TimedCalls(scene)
    count, start = 0, time.perf_counter()
    while count < 3 or time.perf_counter() - start < window:
        trajectory_gradient(scene, setup)
        count += 1
    return timer.seconds / count


def measure_node(args, local_answers):
    """The UR5 backprop and the trajectory gradient through RigidBodyClient (tcpros buffers)."""
    import pool_throughput
    from diff_rigid_body import LocalScene
    from diff_rigid_body.client import RigidBodyClient
    out = {}
    with tempfile.TemporaryDirectory(prefix='drb_local_bench_') as folder:
        graph = pool_throughput.Graph(folder)
        try:
            graph.instance('/ur5', UR5)
            graph.instance('/demo', DEMO)
            pool_throughput.wait_for(['/ur5', '/demo'])
            ur5 = RigidBodyClient('/ur5/rigid_body_server', transport='tcpros').connect()
            r = ur5_backprop_request(LocalScene(urdf_path=UR5))
            same = np.array_equal(ur5.backprop(**r), local_answers['backprop'])
            out['ur5/backprop_K1000_N400'] = dict(node=timed(lambda: ur5.backprop(**r), args.window,
                                                             args.windows), same_bits=bool(same))
            demo = RigidBodyClient('/demo/rigid_body_server', transport='tcpros').connect()
            setup = trajectory_setup(demo)
            loss, gradient = trajectory_gradient(demo, setup)
            same = (loss.tobytes() == local_answers['trajectory'][0].tobytes() and
                    gradient.tobytes() == local_answers['trajectory'][1].tobytes())
            out['trajectory_T1000'] = dict(node=timed(lambda: trajectory_gradient(demo, setup), args.window,
                                                      args.windows), same_bits=bool(same))
        finally:
            graph.stop()
    return out


def same_result(a, b):
    """Field by field (named tuples, lists per body, arrays): the same bits."""
    if isinstance(a, (tuple, list)) and not isinstance(a, str):
        return len(a) == len(b) and all(same_result(x, y) for x, y in zip(a, b))
    if a is None or isinstance(a, str):
        return a == b
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def memory_child(kind, K):
    """In a fresh process: peak RSS [bytes] before and after one K-configuration call, and the
    answer's bytes. The scene is loaded and called once at K = 1 first (its per-thread workspace)."""
    from diff_rigid_body import LocalScene
    scene = LocalScene(urdf_path=UR5)
    bodies = scene.bodies()
    body, d, count = bodies.names[0], int(bodies.dofs[0]), int(bodies.vertex_counts[0])
    q = configurations(K, d)
    vertices = selected_vertices(count, 32)
    call = {'mass_matrix': lambda x: scene.mass_matrix(q=x),
            'positions': lambda x: scene.vertex_jacobians_compact(body, q=x, vertices=vertices,
                                                                  positions_only=True)}[kind]
    call(q[:1])
    maxrss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KiB on Linux
    with open('/proc/self/clear_refs', 'w') as f:
        f.write('5')  # VmHWM := VmRSS: the peak from here on
    before = status_bytes('VmRSS')
    answer = call(q)
    after = status_bytes('VmHWM')
    maxrss_after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    arrays = [x for x in answer if isinstance(x, np.ndarray)]  # every array field (M with cos_theta)
    return dict(kind=kind, K=K, before=before, after=after, maxrss_before=maxrss_before, maxrss_after=maxrss_after,
                answer_bytes=int(sum(x.nbytes for x in arrays)), shape=list(arrays[0].shape))


def status_bytes(field):
    """/proc/self/status's ``field`` (VmRSS, VmHWM) [bytes]."""
    with open('/proc/self/status') as f:
        for line in f:
            if line.startswith(field + ':'):
                return int(line.split()[1]) * 1024
    raise RuntimeError('/proc/self/status: no ' + field)


def measure_memory(K):
    out = []
    for kind in ('mass_matrix', 'positions'):
        text = subprocess.run([sys.executable, os.path.abspath(__file__), '--memory-child', kind, '--memory-k', str(K)],
                              check=True, capture_output=True, text=True).stdout
        out.append(json.loads(text.strip().splitlines()[-1]))
        log('memory: %s: +%.1f MB for an answer of %.1f MB' % (kind, (out[-1]['after'] - out[-1]['before']) / 1e6,
                                                               out[-1]['answer_bytes'] / 1e6))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--out', help='results folder: writes local.json')
    parser.add_argument('--bin', help='folder of drb_bench_local: its core rows take turns with LocalScene')
    parser.add_argument('--quick', action='store_true', help='short windows, one Dask repeat (a smoke run)')
    parser.add_argument('--parts', nargs='+', choices=PARTS, default=list(PARTS), help='what to measure')
    parser.add_argument('--memory-child', choices=['mass_matrix', 'positions'], help=argparse.SUPPRESS)
    parser.add_argument('--memory-k', type=int, default=100000, help='K of the memory batch')
    parser.add_argument('--dask-k', type=int, default=20000, help='K of the Dask batch')
    args = parser.parse_args()
    args.bin = os.path.join(args.bin, 'drb_bench_local') if args.bin else None
    robots = os.path.join(REPO, 'test/robots')  # package:// meshes of the Panda, the UR5 and the humanoid
    os.environ['ROS_PACKAGE_PATH'] = robots + ':' + os.environ.get('ROS_PACKAGE_PATH', '')
    if args.memory_child:
        print(json.dumps(memory_child(args.memory_child, args.memory_k)))
        return 0
    args.window, args.windows, args.dask_repeats = (0.2, 3, 1) if args.quick else (0.5, 7, 3)
    started, load_at_start = time.monotonic(), os.getloadavg()[0]
    result = dict(machine='%s, %d cores, Python %s' % (platform.machine(), os.cpu_count(), platform.python_version()),
                  quick=args.quick, window_s=args.window, windows=args.windows)
    if 'kernel' in args.parts:
        log('kernel rows (LocalScene side)')
        result['kernel'] = measure_kernel_side(args)
    if 'trajectory' in args.parts or 'node' in args.parts:
        log('trajectory gradient, T = 1000, in process')
        result['trajectory'], trajectory_answer = measure_trajectory(args)
    if 'node' in args.parts:
        from diff_rigid_body import LocalScene
        backprop = LocalScene(urdf_path=UR5)
        answers = dict(backprop=backprop.backprop(**ur5_backprop_request(backprop)), trajectory=trajectory_answer)
        log('node (tcpros buffer transport, own roscore)')
        result['node'] = measure_node(args, answers)
    if 'memory' in args.parts:
        log('memory, K = %d (fresh processes)' % args.memory_k)
        result['memory'] = measure_memory(args.memory_k)
    if 'dask' in args.parts:
        log('dask LocalCluster, K = %d' % args.dask_k)
        from local_dask_throughput import measure_dask  # bench/, beside this file
        result['dask'] = measure_dask(args)
    result['seconds'] = time.monotonic() - started
    result['load'] = [load_at_start, os.getloadavg()[0]]  # 1-minute load average: how quiet the machine was
    text = json.dumps(result, indent=1)
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, 'local.json'), 'w') as f:
            f.write(text)
    print(text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
