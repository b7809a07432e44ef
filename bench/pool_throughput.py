#!/usr/bin/python3
"""Throughput of diff_rigid_body.RigidBodyPool over 1, 2 and 4 instances on this machine.

    source $DRB_WORKSPACE/devel/setup.bash && bench/pool_throughput.py --output pool.md

(scripts/bench runs it and puts its report in docs/benchmarks.md, "Several instances").

Starts its own master on a free port and four rigid_body_server instances per scene (separate
processes, ~benchmark_services on), then, for each workload and each pool size, runs back-to-back
calls for a time window and counts them; windows of the pool sizes are interleaved over the repeats
so that a busy phase of a shared machine lands on every size alike (medians are reported, and the
load the machine was under). Workloads (K = 1000 configurations per call):
  * backprop on the Panda (8 coordinates), dL/dp for all 1,130 collision vertices (27 MB up) and
    for 64 of them (1.5 MB up);
  * get_mass_matrix on simple_humanoid with its waist floating (35 coordinates; 9.8 MB down).
Every pool answer is checked bit for bit against one instance's. Also measured: the same bytes
echoed by the nodes (~echo: the transport alone, split in n streams as a pool of n splits them),
the CPU each process used,
and one instance killed mid-call (failover). The report and the N-host model: bench/pool_report.py.
"""
import argparse
import os
import platform
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import pool_report  # noqa: E402  (bench/, beside this script)

PANDA = os.path.join(REPO, 'test/robots/drb_example_robot_data/robots/panda_description/urdf/panda.urdf')
HUMANOID = os.path.join(REPO, 'test/robots/drb_example_robot_data/robots/simple_humanoid_description/urdf/'
                              'simple_humanoid.urdf')
SIZES = (1, 2, 4)
K = 1000


def log(text):
    print('[pool bench] ' + text, file=sys.stderr, flush=True)


def free_port():
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def floating_humanoid(folder):
    """simple_humanoid with its `waist` joint made floating (35 coordinates), written to ``folder``."""
    with open(HUMANOID) as f:
        text = f.read()
    text, count = re.subn(r'<joint name="waist" type="fixed">', '<joint name="waist" type="floating">', text)
    if count != 1:
        raise RuntimeError('simple_humanoid.urdf: no fixed waist joint to make floating')
    path = os.path.join(folder, 'simple_humanoid_floating.urdf')
    with open(path, 'w') as f:
        f.write(text)
    return path


class Graph(object):
    """A master and rigid_body_server instances (own process groups); stop() ends them all."""

    def __init__(self, folder):
        self.folder, self.processes = folder, []
        port = free_port()
        os.environ['ROS_MASTER_URI'] = 'http://127.0.0.1:%d' % port
        robots = os.path.join(REPO, 'test/robots')  # the Panda's and the humanoid's package:// meshes
        os.environ['ROS_PACKAGE_PATH'] = robots + ':' + os.environ.get('ROS_PACKAGE_PATH', '')
        self._start('master', ['rosmaster', '--core', '-p', str(port)])
        time.sleep(1.0)

    def _start(self, name, argv):
        output = open(os.path.join(self.folder, name.strip('/').replace('/', '_') + '.log'), 'w')
        self.processes.append(subprocess.Popen(argv, stdout=output, stderr=subprocess.STDOUT,
                                               start_new_session=True))
        return self.processes[-1]

    def instance(self, namespace, urdf):
        """rigid_body_server in ``namespace`` on ``urdf`` (1 Hz tf, ~benchmark_services); its process."""
        return self._start(namespace, ['rosrun', 'diff_rigid_body', 'rigid_body_server', '__ns:=' + namespace,
                                       '_urdf_path:=' + urdf, '_frame_prefix:=%s/' % namespace.strip('/'),
                                       '_publish_rate:=1.0', '_benchmark_services:=true'])

    def stop(self):
        for process in reversed(self.processes):
            if process.poll() is None:
                try:
                    os.killpg(process.pid, signal.SIGINT)
                    process.wait(timeout=10)
                except (subprocess.TimeoutExpired, ProcessLookupError):
                    os.killpg(process.pid, signal.SIGKILL)


def cpu_seconds(pid):
    """User + system CPU time [s] of a process (/proc/<pid>/stat)."""
    with open('/proc/%d/stat' % pid) as f:
        fields = f.read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def machine_load():
    """(1-minute load average, compilers running): how quiet the machine was."""
    compilers = subprocess.run(['pgrep', '-c', 'cc1plus'], capture_output=True, text=True).stdout.strip() or '0'
    return float(open('/proc/loadavg').read().split()[0]), int(compilers)


def first_touch_cost(megabytes=64):
    """[us] per 4 KiB page to write memory just allocated (page faults; costly on some VMs)."""
    start = time.perf_counter()
    np.ones(megabytes << 17)  # 8-byte values
    return 1e6 * (time.perf_counter() - start) / (megabytes << 8)


def window(call, seconds, pids, warm_up=0.0):
    """Calls ``call()`` back to back for ``warm_up`` seconds (at least 3 calls; not counted), then
    for ``seconds``: (calls/s, CPU cores used per pid, by this client). The warm-up matters: a node's
    service threads each have their own malloc arena, whose pages a large request faults in before
    the calls that follow reuse them."""
    start = time.monotonic()
    for count in range(1 << 30):
        if count >= 3 and time.monotonic() - start >= warm_up:
            break
        call()
    before = [cpu_seconds(pid) for pid in pids]
    client_before, count, start = time.process_time(), 0, time.monotonic()
    while time.monotonic() - start < seconds:
        call()
        count += 1
    elapsed = time.monotonic() - start
    cores = [(cpu_seconds(pid) - b) / elapsed for pid, b in zip(pids, before)]
    return count / elapsed, cores, (time.process_time() - client_before) / elapsed


class Workload(object):
    """One benchmark: a body, a pool method and its arguments, and the bytes of one call."""

    def __init__(self, name, method, arguments, request_bytes, response_bytes):
        self.name, self.method, self.arguments = name, method, arguments
        self.request_bytes, self.response_bytes = request_bytes, response_bytes

    def run(self, client):
        return getattr(client, self.method)(*self.arguments[0], **self.arguments[1])


def workloads(scene):
    """The workloads of a scene ('panda' or 'humanoid'), K = 1000 random configurations each."""
    rng = np.random.default_rng(7)
    if scene == 'panda':
        q = rng.uniform(-1.0, 1.0, (K, 8))
        q[:, 7] = 0.02  # the finger (prismatic) [m]
        out = []
        for vertices in (None, np.linspace(0, 1129, 64).astype(np.uint32)):
            N = 1130 if vertices is None else len(vertices)
            g = rng.standard_normal((K, N, 3))
            out.append(Workload('Panda backprop, K = %d, %d vertices' % (K, N), 'backprop',
                                (('panda_link1', g, q, vertices), {}),
                                g.nbytes + q.nbytes + (0 if vertices is None else vertices.nbytes), 8 * 8 * K))
        return out
    q = rng.uniform(-0.5, 0.5, (K, 1, 35))
    return [Workload('Humanoid M, K = %d, 35 coordinates' % K, 'mass_matrix', ((), {'q': q}), q.nbytes,
                     8 * (35 * 35 + 1) * K)]  # M and cos_theta


def same_answer(a, b):
    if isinstance(a, tuple):
        return all(same_answer(x, y) for x, y in zip(a, b) if not isinstance(x, list))
    return np.asarray(a).tobytes() == np.asarray(b).tobytes()


def wait_for(namespaces, timeout=120.0):
    import rospy
    for namespace in namespaces:
        rospy.wait_for_service(namespace + '/rigid_body_server/get_bodies', timeout=timeout)


def echo_rate(namespaces, workload, seconds):
    """The transport alone for a pool over ``namespaces``: each of n streams (one per namespace,
    each its own tcpros.ServiceConnection in its own thread) echoes 1/n of a call's bytes, as the
    pool's shards carry them; calls/s of the whole call (the slowest stream's rate)."""
    from rospy.numpy_msg import numpy_msg
    from diff_rigid_body.client_arrays import to_wire
    from diff_rigid_body.srv import Echo
    from diff_rigid_body.tcpros import ServiceConnection
    shards = len(namespaces)
    message = to_wire(numpy_msg(Echo._request_class)(data=np.zeros(workload.request_bytes // 8 // shards),
                                                     response_size=workload.response_bytes // 8 // shards))
    counts, stop = [0] * len(namespaces), time.monotonic() + seconds

    def stream(i, connection):
        while time.monotonic() < stop:
            connection.call(message)
            counts[i] += 1
    connections = [ServiceConnection(ns + '/rigid_body_server/echo', Echo, 30.0) for ns in namespaces]
    threads = [threading.Thread(target=stream, args=(i, c)) for i, c in enumerate(connections)]
    start = time.monotonic()
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return min(counts) / (time.monotonic() - start)


def failover_trial(namespaces, victim_pid, workload, calls):
    """``calls`` pool calls over ``namespaces``; the last instance's process (``victim_pid``) is
    frozen when its shard of the third call is sent and killed 0.3 s later: the call waits on a node
    that dies. Returns (failed calls, answers equal to one instance's, the pool's log)."""
    from diff_rigid_body.client import RigidBodyClient
    from diff_rigid_body.pool import RigidBodyPool
    lines = []
    pool = RigidBodyPool(namespaces, call_timeout=30.0, log=lines.append)
    reference = workload.run(RigidBodyClient(namespaces[0] + '/rigid_body_server'))
    instance = pool.instances[-1]
    original, sent = instance.client.send, [0]

    def send(name, message):
        sent[0] += 1
        if sent[0] == 3:
            os.kill(victim_pid, signal.SIGSTOP)
            threading.Timer(0.3, os.kill, (victim_pid, signal.SIGKILL)).start()
        return original(name, message)
    instance.client.send = send
    failed, equal = 0, 0
    for _ in range(calls):
        try:
            equal += same_answer(workload.run(pool), reference)
        except Exception as error:  # counted: the target is none
            failed += 1
            lines.append('call failed: %s' % error)
    return failed, equal, lines


def measure_scene(graph, scene, urdf, args):
    from diff_rigid_body.client import RigidBodyClient
    from diff_rigid_body.pool import RigidBodyPool
    namespaces = ['/%s%d' % (scene, i) for i in range(1, 5)]
    processes = [graph.instance(namespace, urdf) for namespace in namespaces]
    wait_for(namespaces)
    pids = [p.pid for p in processes]  # rosrun execs the node: same pid
    clients = {'client': RigidBodyClient(namespaces[0] + '/rigid_body_server').connect()}
    clients.update(('pool %d' % n, RigidBodyPool(namespaces[:n])) for n in SIZES)
    results = []
    for workload in workloads(scene):
        log(workload.name)
        reference = workload.run(clients['client'])
        equal = dict((label, same_answer(workload.run(c), reference)) for label, c in clients.items())
        samples = dict((label, []) for label in clients)
        for label, client in clients.items():
            window(lambda: workload.run(client), 0.0, pids, warm_up=args.seconds)
        for repeat in range(args.repeats):
            for label, client in clients.items():
                samples[label].append(window(lambda: workload.run(client), args.seconds, pids) + machine_load())
        floor = dict((n, echo_rate(namespaces[:n], workload, args.seconds)) for n in SIZES)
        results.append(dict(workload=workload, equal=equal, samples=samples, echo=floor))
    failover = failover_trial(namespaces[2:4], pids[3], workloads(scene)[0], 8) if scene == 'panda' else None
    return results, failover


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--seconds', type=float, default=3.0, help='length of one measurement window [s]')
    parser.add_argument('--repeats', type=int, default=3, help='windows per pool size (median reported)')
    parser.add_argument('--output', required=True, help='markdown report to write')
    args = parser.parse_args()
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix='drb_pool_bench_') as folder:
        graph = Graph(folder)
        try:
            scenes = {}
            for scene, urdf in (('panda', PANDA), ('humanoid', floating_humanoid(folder))):
                scenes[scene] = measure_scene(graph, scene, urdf, args)
        finally:
            graph.stop()
    machine = '%s, %d cores, Python %s; writing fresh memory costs %.1f us per 4 KiB page' % (
        platform.machine(), os.cpu_count(), platform.python_version(), first_touch_cost())
    text = pool_report.report(scenes, args, machine, time.monotonic() - start)
    with open(args.output, 'w') as f:
        f.write(text)
    print(text)
    log('wrote %s' % args.output)


if __name__ == '__main__':
    sys.exit(main())
