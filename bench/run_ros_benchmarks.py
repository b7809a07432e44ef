#!/usr/bin/python3
"""Service-level and scene-scale benchmarks through the real node.

Starts its own roscore on a free loopback port, then
  * services: rigid_body_server (~benchmark_services:=true) on a generated
    scene of bodies v10 .. v1000000 (N vertices each), driven by the C++
    client drb_bench_service (persistent connections, TCP_NODELAY);
  * scene scale: rigid_body_server on generated URDFs of 1, 100 and 10,000
    bodies: load time, resident memory (VmRSS), and the CPU the node uses
    publishing tf at 50 Hz (from /proc/<pid>/stat), with no tf subscriber and
    with one (drb_bench_service tf_sink);
  * client trajectories: bench/client_trajectory.py (PyTorch through the
    Python client, batched against per-frame calls) on the default scene.
Writes <out>/service.json, <out>/scene.json and <out>/client_trajectory.md. Everything it starts is
stopped on exit. Run by scripts/bench; needs the ROS environment sourced.
"""
import argparse
import json
import os
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
import xmlrpc.client

CLOCK_TICKS = os.sysconf("SC_CLK_TCK")


def log(message):
    print("[bench] " + message, file=sys.stderr, flush=True)


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Process:
    """A child in its own process group; stdout lines are timestamped."""

    def __init__(self, argv, env, log_path):
        self.start = time.monotonic()
        self.log = open(log_path, "w")
        self.proc = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     start_new_session=True, text=True)
        self.lines = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append((time.monotonic(), line))
            self.log.write(line)
            self.log.flush()

    def first_line_time(self, needle):
        for stamp, line in self.lines:
            if needle in line:
                return stamp - self.start
        return None

    @property
    def pid(self):
        return self.proc.pid

    def stop(self):
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, signal.SIGINT)
                self.proc.wait(timeout=10)
            except (subprocess.TimeoutExpired, ProcessLookupError):
                try:
                    os.killpg(self.proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                self.proc.wait()
        self.reader.join(timeout=5)
        self.log.close()


class Master:
    def __init__(self, uri):
        self.proxy = xmlrpc.client.ServerProxy(uri)

    def up(self):
        try:
            code, _, _ = self.proxy.getPid("/drb_bench")
            return code == 1
        except (OSError, xmlrpc.client.Error):
            return False

    def has_service(self, name):
        try:
            code, _, _ = self.proxy.lookupService("/drb_bench", name)
            return code == 1
        except (OSError, xmlrpc.client.Error):
            return False


def wait_for(predicate, timeout, what, process=None):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        if process is not None and process.proc.poll() is not None:
            raise RuntimeError(f"{what}: the process exited with {process.proc.returncode}")
        time.sleep(0.01)
    raise RuntimeError(f"timed out after {timeout} s waiting for {what}")


def proc_cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS  # utime + stime


def proc_rss_bytes(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    return 0


def cpu_fraction(pid, seconds):
    """CPU time of `pid` over `seconds` of wall time, as a fraction of one core."""
    c0, t0 = proc_cpu_seconds(pid), time.monotonic()
    time.sleep(seconds)
    return (proc_cpu_seconds(pid) - c0) / (time.monotonic() - t0)


# ---------------------------------------------------------------------------
# Generated scenes.

def write_grid_ply(path, count):
    """A binary PLY grid of exactly `count` distinct vertices, all used by faces."""
    width = max(2, int(count ** 0.5 + 0.999999))
    vertices = []
    for i in range(count):
        r, c = divmod(i, width)
        vertices.append((c * 1e-3, r * 1e-3, 1e-3 * ((r * 7 + c * 13) % 17)))
    def index(r, c):
        i = r * width + c
        return i if c < width and i < count else None
    faces = []
    rows = (count + width - 1) // width
    for r in range(rows - 1):
        for c in range(width - 1):
            a, b, d, e = index(r, c), index(r + 1, c), index(r, c + 1), index(r + 1, c + 1)
            if a is not None and b is not None and d is not None:
                faces.append((a, b, d))
            if d is not None and b is not None and e is not None:
                faces.append((d, b, e))
    if rows == 1:  # one row: a strip
        faces = [(i, i + 1, i + 2) for i in range(count - 2)]
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {count}\nproperty float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(b"".join(struct.pack("<fff", *v) for v in vertices))
        f.write(b"".join(struct.pack("<Biii", 3, *t) for t in faces))


INERTIAL = ('<inertial><origin xyz="0 0 0"/><mass value="2.5"/>'
            '<inertia ixx="0.04" ixy="0.001" ixz="-0.002" iyy="0.05" iyz="0.003" izz="0.06"/></inertial>')


def service_scene(directory, counts):
    os.makedirs(directory, exist_ok=True)
    links, joints = [], []
    for n in counts:
        mesh = os.path.join(directory, f"grid_{n}.ply")
        if not os.path.exists(mesh):
            write_grid_ply(mesh, n)
        links.append(f'<link name="v{n}">{INERTIAL}<collision><geometry><mesh filename="{mesh}"/></geometry>'
                     '</collision></link>')
        joints.append(f'<joint name="j{n}" type="floating"><parent link="world"/><child link="v{n}"/></joint>')
    path = os.path.join(directory, "service_scene.urdf")
    with open(path, "w") as f:
        f.write('<?xml version="1.0"?>\n<robot name="service_bench"><link name="world"/>\n')
        f.write("\n".join(links + joints))
        f.write("\n</robot>\n")
    return path


def scale_scene(directory, bodies):
    os.makedirs(directory, exist_ok=True)
    path = os.path.join(directory, f"scene_{bodies}.urdf")
    with open(path, "w") as f:
        f.write('<?xml version="1.0"?>\n<robot name="scale_bench"><link name="world"/>\n')
        for i in range(bodies):
            x, y = (i % 100) * 0.5, (i // 100) * 0.5
            f.write(f'<link name="b{i}">{INERTIAL}<collision><geometry><box size="0.2 0.3 0.4"/></geometry>'
                    f'</collision></link><joint name="j{i}" type="floating"><origin xyz="{x} {y} 1" rpy="0.1 0.2 0.3"/>'
                    f'<parent link="world"/><child link="b{i}"/></joint>\n')
        f.write("</robot>\n")
    return path


# ---------------------------------------------------------------------------

def start_node(args, env, urdf, log_path, extra=()):
    argv = [os.path.join(args.bin, "rigid_body_server"), "__name:=rigid_body_server", f"_urdf_path:={urdf}",
            "_publish_rate:=50.0"] + list(extra)
    return Process(argv, env, log_path)


def run_services(args, env, master):
    counts = [10, 100, 1000, 10000, 100000, 1000000]
    urdf = service_scene(os.path.join(args.out, "service_scene"), counts)
    node = start_node(args, env, urdf, os.path.join(args.out, "node_service.log"), ["_benchmark_services:=true"])
    try:
        wait_for(lambda: master.has_service("/rigid_body_server/ping"), 300, "the node's services", node)
        log("services: node up; running the client")
        client = subprocess.run([os.path.join(args.bin, "drb_bench_service"), "services",
                                 os.path.join(args.out, "service.json"), str(args.budget)], env=env)
        if client.returncode != 0:
            raise RuntimeError(f"drb_bench_service exited with {client.returncode}")
    finally:
        node.stop()


def run_scene(args, env, master):
    results = []
    for bodies in (1, 100, 10000):
        urdf = scale_scene(os.path.join(args.out, "scale_scenes"), bodies)
        node = start_node(args, env, urdf, os.path.join(args.out, f"node_scene_{bodies}.log"))
        try:
            wait_for(lambda: master.has_service("/rigid_body_server/get_bodies"), 300, "the node", node)
            ready = time.monotonic() - node.start
            wait_for(lambda: node.first_line_time("serving") is not None, 10, "the node's log")
            loaded = node.first_line_time("serving")
            time.sleep(1.0)
            rss = proc_rss_bytes(node.pid)
            idle = cpu_fraction(node.pid, args.cpu_seconds)
            sink_out = os.path.join(args.out, f"tf_sink_{bodies}.json")
            sink = subprocess.Popen([os.path.join(args.bin, "drb_bench_service"), "tf_sink", sink_out,
                                     str(args.cpu_seconds + 1.0)], env=env)
            time.sleep(1.0)  # connect and receive the first messages
            busy = cpu_fraction(node.pid, args.cpu_seconds)
            sink_cpu = proc_cpu_seconds(sink.pid)
            sink.wait(timeout=60)
            with open(sink_out) as f:
                received = json.load(f)
            results.append({"bodies": bodies, "log_line_s": loaded, "services_ready_s": ready, "vm_rss_bytes": rss,
                            "cpu_no_subscriber": idle, "cpu_one_subscriber": busy, "tf_sink": received,
                            "tf_sink_cpu_s": sink_cpu})
            log(f"scene: {bodies} bodies: ready {ready:.2f} s, RSS {rss / 2**20:.1f} MiB, "
                f"CPU {100 * idle:.1f}% / {100 * busy:.1f}% (no / one tf subscriber)")
        finally:
            node.stop()
    with open(os.path.join(args.out, "scene.json"), "w") as f:
        json.dump({"publish_rate_hz": 50.0, "cpu_window_s": args.cpu_seconds, "scenes": results}, f, indent=1)


def run_client_trajectory(args, env, master):
    """bench/client_trajectory.py (PyTorch through the Python client) against the node on the default scene."""
    here = os.path.dirname(os.path.abspath(__file__))
    urdf = os.path.join(here, "..", "urdf", "demo_scene.urdf")
    node = start_node(args, env, urdf, os.path.join(args.out, "node_client_trajectory.log"),
                      ["_benchmark_services:=true"])
    try:
        wait_for(lambda: master.has_service("/rigid_body_server/backprop"), 300, "the node", node)
        log("client trajectories: node up; running bench/client_trajectory.py")
        client = subprocess.run([sys.executable, os.path.join(here, "client_trajectory.py"), "--server",
                                 "/rigid_body_server", "--transports", "tcpros", "rospy", "--floor",
                                 "--output", os.path.join(args.out, "client_trajectory.md")],
                                env=env)
        if client.returncode != 0:
            raise RuntimeError(f"client_trajectory.py exited with {client.returncode}")
    finally:
        node.stop()


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--bin", required=True, help="folder of rigid_body_server and drb_bench_service")
    parser.add_argument("--out", required=True)
    parser.add_argument("--budget", type=float, default=0.5, help="seconds per service measurement")
    parser.add_argument("--cpu-seconds", type=float, default=3.0)
    parser.add_argument("--only", choices=["services", "scene", "client"], default=None,
                        help="run only the service-level part, the scene-scale part or the PyTorch client "
                             "trajectories (default: all)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    port = free_port()
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = f"http://127.0.0.1:{port}"
    env["ROS_HOSTNAME"] = "127.0.0.1"
    env.pop("ROS_IP", None)
    env["ROS_LOG_DIR"] = os.path.join(args.out, "ros_logs")
    env["ROSCONSOLE_STDOUT_LINE_BUFFERED"] = "1"  # the node's log lines arrive as printed (load time)
    master = Master(env["ROS_MASTER_URI"])
    log(f"roscore -p {port}")
    core = Process(["roscore", "-p", str(port)], env, os.path.join(args.out, "roscore.log"))
    try:
        wait_for(master.up, 60, "roscore", core)
        if args.only in (None, "services"):
            run_services(args, env, master)
        if args.only in (None, "scene"):
            run_scene(args, env, master)
        if args.only in (None, "client"):
            run_client_trajectory(args, env, master)
    finally:
        core.stop()


if __name__ == "__main__":
    main()
