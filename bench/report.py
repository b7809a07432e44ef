#!/usr/bin/python3
"""Turns the JSON written by the benchmark binaries into docs/benchmarks.md and
the PNG plots beside it. Run by scripts/bench (Debian's python3, numpy,
matplotlib).

  report.py --results DIR --docs DIR --workspace WS --repo REPO
"""
import argparse
import datetime
import os
import platform
import re
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from report_format import NOT_NODE, fmt_ratio, fmt_time, kernel_table, load, md_table, verdict  # noqa: E402
from report_articulated import section_articulated  # noqa: E402
from report_gimbal import section_gimbal  # noqa: E402
from report_local import section_from as section_local  # noqa: E402
from report_kernels import (plot_kernels, section_backprop, section_floors, section_jacobians,  # noqa: E402
                            section_mass_matrix)

# ---------------------------------------------------------------------------
# Machine.


def run(argv):
    try:
        return subprocess.run(argv, capture_output=True, text=True, timeout=20).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def machine(workspace, kernels, repo, results):
    info = {}
    cpuinfo = open("/proc/cpuinfo").read()
    m = re.search(r"model name\s*:\s*(.*)", cpuinfo)
    info["CPU"] = m.group(1).strip() if m else platform.processor()
    info["cores (logical)"] = str(os.cpu_count())
    lscpu = run(["lscpu"])
    for key in ("Thread(s) per core", "Core(s) per socket", "L2 cache", "L3 cache", "Hypervisor vendor"):
        m = re.search(re.escape(key) + r":\s*(.*)", lscpu)
        if m:
            info[key] = m.group(1).strip()
    flags = re.search(r"flags\s*:\s*(.*)", cpuinfo)
    if flags:
        have = set(flags.group(1).split())
        info["SIMD available"] = " ".join(f for f in ("sse2", "avx", "avx2", "fma", "avx512f") if f in have)
    mem = re.search(r"MemTotal:\s*(\d+)", open("/proc/meminfo").read())
    if mem:
        info["memory"] = f"{int(mem.group(1)) / 2**20:.1f} GiB"
    info["OS"] = run(["sh", "-c", ". /etc/os-release && echo $PRETTY_NAME"]) + ", kernel " + platform.release()
    cache = os.path.join(workspace, "build", "CMakeCache.txt")
    compiler, build_type = "", ""
    if os.path.exists(cache):
        text = open(cache).read()
        m = re.search(r"CMAKE_CXX_COMPILER:\w+=(.*)", text)
        compiler = m.group(1) if m else ""
        m = re.search(r"CMAKE_BUILD_TYPE:\w+=(.*)", text)
        build_type = m.group(1) if m else ""
    info["compiler"] = run([compiler or "c++", "--version"]).splitlines()[0] if run([compiler or "c++", "--version"]) else "?"
    flags_make = os.path.join(workspace, "build", "diff_rigid_body", "CMakeFiles", "drb_bench_kernels.dir", "flags.make")
    if os.path.exists(flags_make):
        m = re.search(r"CXX_FLAGS = (.*)", open(flags_make).read())
        info["flags (bench and kernels)"] = (m.group(1).strip() if m else "?") + f" (CMAKE_BUILD_TYPE={build_type})"
    versions = run(["dpkg-query", "-W", "-f=${Package} ${Version}\\n", "libeigen3-dev", "liborocos-kdl-dev",
                    "libmujoco-dev", "libbenchmark-dev", "libmpfrc++-dev", "libmpfr-dev"])
    info["libraries"] = ", ".join(versions.splitlines())
    ctx = kernels.get("context", {})
    if ctx:
        info["load average at the kernel run"] = ", ".join(f"{x:.2f}" for x in ctx.get("load_avg", []))
        if ctx.get("library_build_type") == "debug":
            info["note"] = ("Debian's libbenchmark reports itself as a debug build; that affects only its "
                            "own loop overhead, not the code measured")
    quiet = os.path.join(results, "quiet.txt")
    samples = [line.split() for line in open(quiet)] if os.path.exists(quiet) else []
    samples = [(int(c), float(load)) for c, load in samples if c.isdigit()]
    if samples:
        busy = sum(1 for c, _ in samples if c > 0)
        info["compilers (cc1plus) running during the kernel run"] = (
            f"in {busy} of {len(samples)} samples 5 s apart (at most {max(c for c, _ in samples)}); "
            f"1-minute load {min(x for _, x in samples):.2f} … {max(x for _, x in samples):.2f}")
    commit = run(["git", "-C", repo, "rev-parse", "--short", "HEAD"])
    dirty = run(["git", "-C", repo, "status", "--porcelain", "--untracked-files=no"])
    info["source"] = commit + (" + uncommitted changes" if dirty else "")
    return info


# ---------------------------------------------------------------------------
# Sections.


def section_inertia(inertia, docs):
    text = ["## 4. Inertia: particles (eq. 17) against the exact polyhedral integral", ""]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    rows = []
    for mesh, marker in zip(inertia["meshes"], ("o", "s")):
        pts = mesh["points"]
        xs = [p["inertia_error"] for p in pts]
        ys = [p["seconds"] * 1e3 for p in pts]
        label = mesh["name"]
        ax.loglog(xs, ys, marker=marker, label=f"{label}: particles, N = 10² … 10⁶")
        for p in pts:
            if p["target"] in (100, 10000, 1000000):
                ax.annotate(f"N={p['samples']:,}", (p["inertia_error"], p["seconds"] * 1e3), fontsize=7,
                            textcoords="offset points", xytext=(4, 4))
        ax.axhline(mesh["exact_seconds"] * 1e3, linestyle="--", linewidth=0.8, color=ax.lines[-1].get_color(),
                   label=f"{mesh['name']}: exact integral, error ~1e-16")
        for p in pts:
            rows.append([mesh["name"], f"{p['samples']:,}", NOT_NODE, fmt_time(p["seconds"] * 1e9),
                         f"{p['mass_error']:.2g}",
                         f"{p['com_error']:.2g}", f"{p['inertia_error']:.2g}"])
        rows.append([mesh["name"], "exact (meshMassProperties)",
                     "yes, at load: a mesh link without `<inertial>`, with `~density` (urdf_scene.cpp)",
                     fmt_time(mesh["exact_seconds"] * 1e9), "—", "—",
                     "—"])
    ax.set_xlabel("max relative error of the inertia (vs exact polyhedral integral)")
    ax.set_ylabel("time per evaluation [ms]")
    ax.set_title("Inertia: speed against error")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(docs, "benchmarks_inertia.png"), dpi=120)
    plt.close(fig)
    text += ["![inertia: time against error](benchmarks_inertia.png)", "",
             "Particles on a regular grid inside the mesh (`particleMassProperties`, scanline ray casting) against "
             "`meshMassProperties` (signed tetrahedra). Errors: mass relative, COM relative to the bounding-box "
             "diagonal, inertia max-entry relative (about the COM). The exact integral is both faster and exact "
             "for any closed mesh: particles only make sense where no closed surface exists.", "",
             md_table(["mesh", "samples", "node runs", "time", "mass error", "COM error", "inertia error"], rows)]
    return "\n".join(text)


BENCH_SERVICE = "`~ping` / `~echo`: benchmark services (`~benchmark_services`), no query"
SERVICE_NODE = {
    "get_vertex_jacobians": "`SceneQueries::vertexJacobians` → `vertexJacobians` → `vertexPositionsAndJacobians` (free object)",
    "compact_rotation_block": "`SceneQueries::vertexRotationJacobians<double>`",
    "compact_rotation_block_f32": "`SceneQueries::vertexRotationJacobians<float>`",
    "compact_positions_only": "`SceneQueries::vertexRotationJacobians<double>`, positions only",
    "backprop": "`SceneQueries::backpropConfigurations` → `vertexBackprop` → `backpropagateVertexGradients` (free "
                "object, by coordinate)"}


def section_service(service, targets):
    t = {x["name"]: x for x in service["timings"]}
    us = lambda x: f"{x * 1e6:.1f} µs" if x < 1e-2 else f"{x * 1e3:.1f} ms"  # noqa: E731
    text = ["## 5. Service level, through the real node",
            "",
            "A C++ roscpp client with persistent `ServiceClient`s calls the node started with "
            "`~benchmark_services:=true` on a generated scene of bodies with 10 … 10⁶ vertices, on its own roscore "
            "on a free loopback port. Median wall time per call (quartiles in brackets). Each service is timed "
            "alternately with its reference (`~ping`, or `~echo` moving the same payload bytes each way), so both "
            "see the same machine load. Default sockets; TCP_NODELAY (set on the client's sockets afterwards, "
            "since roscpp's service client takes no TransportHints) is shown for the small calls.",
            ""]
    ping = t.get("ping")
    mm = t.get("get_mass_matrix")
    rows = []
    mass = "`SceneQueries::massMatrices` → `massMatrices` → `massMatrixBatch` (free object)"
    for name, label, node in (("ping", "~ping (empty)", BENCH_SERVICE),
                              ("get_mass_matrix", "~get_mass_matrix, 1 matrix", mass + " (1 state)"),
                              ("ping_nodelay", "~ping, client sockets with TCP_NODELAY", BENCH_SERVICE),
                              ("get_mass_matrix_nodelay", "~get_mass_matrix, client sockets with TCP_NODELAY",
                               mass + " (1 state)"),
                              ("get_mass_matrix_K1000", "~get_mass_matrix, K = 1000 configurations",
                               mass + " (1000 states)"),
                              ("echo_for_get_mass_matrix_K1000", "~echo, same bytes as K = 1000", BENCH_SERVICE)):
        x = t.get(name)
        if x:
            rows.append([label, node, f"{us(x['median_s'])} [{us(x['p25_s'])}, {us(x['p75_s'])}]", x["calls"],
                         fmt_ratio(x["median_s"] / ping["median_s"]) if ping else "n/a"])
    text.append(md_table(["call", "node runs", "round trip", "calls", "÷ ~ping"], rows))
    if ping and mm:
        r = mm["median_s"] / ping["median_s"]
        targets.append(["get_mass_matrix round trip ≤ 1.3× the empty service", f"{r:.3g}×",
                        verdict(r <= 1.3, "" if r <= 1.3 else f"over by {r / 1.3:.2g}×")])
    # Vertex services.
    rows = []
    worst = {"get_vertex_jacobians": 0, "backprop": 0}
    sizes = sorted({int(n.split("/")[1]) for n in t if n.startswith("get_vertex_jacobians/")})
    for n in sizes:
        for svc, label in (("get_vertex_jacobians", "get_vertex_jacobians"),
                           ("compact_rotation_block", "compact: rotation block"),
                           ("compact_rotation_block_f32", "compact: rotation block, float32"),
                           ("compact_positions_only", "compact: positions only"), ("backprop", "backprop")):
            x, e = t.get(f"{svc}/{n}"), t.get(f"echo_for_{svc}/{n}")
            if not x or not e:
                continue
            r = x["median_s"] / e["median_s"]
            if svc in worst:
                worst[svc] = max(worst[svc], r)
            nbytes = max(x["request_bytes"], x["response_bytes"])
            err = ""
            if "jacobian_rel_error" in x:
                err = f"pos {x['position_rel_error']:.2g}, Jr {x['jacobian_rel_error']:.2g}"
            rows.append([f"{n:,}", label, SERVICE_NODE[svc], f"{nbytes / 1e6:.3g} MB", us(x["median_s"]),
                         us(e["median_s"]), fmt_ratio(r), f"{nbytes / x['median_s'] / 1e9:.2g} GB/s", err])
    text += ["", "### Vertex services against a same-size echo", "",
             "The echo (`~echo`, a benchmark service: the payload copied back, no query) is not on the node's "
             "product path; it is the reference each service is timed against.", "",
             md_table(["vertices", "service", "node runs", "payload", "service", "echo", "÷ echo", "payload rate",
                       "reduced transport error vs full answer"], rows)]
    text += section_dynamics_services(t, us, targets)
    for svc in ("get_vertex_jacobians", "backprop"):
        if worst[svc]:
            r = worst[svc]
            targets.append([f"{svc} ≤ 1.5× the same-size echo (worst size)", f"{r:.3g}×",
                            verdict(r <= 1.5, "" if r <= 1.5 else f"over by {r / 1.5:.2g}×")])
    return "\n".join(text)


def section_dynamics_services(t, us, targets):
    """~inverse_dynamics and ~forward_dynamics of one free body against a same-size echo: K = 1 (the
    service's own cost) and K = 1000 with derivatives (the node's computation on top)."""
    rows, worst = [], {1: 0.0, 1000: 0.0}
    compute = {}
    for service in ("inverse_dynamics", "forward_dynamics"):
        for K in (1, 1000):
            name = f"{service}/K{K}"
            x, e = t.get(name), t.get("echo_for_" + name)
            if not x or not e:
                continue
            r = x["median_s"] / e["median_s"]
            worst[K] = max(worst[K], r)
            if K > 1:
                compute[service] = (x["median_s"] - e["median_s"]) / K
            rows.append([f"{service}, K = {K}" + (", derivatives" if K > 1 else ""),
                         f"{x['request_bytes'] / 1e3:.3g} kB up, {x['response_bytes'] / 1e3:.3g} kB down",
                         us(x["median_s"]), us(e["median_s"]), fmt_ratio(r)])
    if not rows:
        return []
    targets.append(["Issue 20: dynamics service round trips ≤ 1.3× a same-size echo, K = 1", f"{worst[1]:.3g}×",
                    verdict(worst[1] <= 1.3, "" if worst[1] <= 1.3 else f"over by {worst[1] / 1.3:.2g}×")])
    per = ", ".join(f"{s.split('_')[0]} {c * 1e6:.2g} µs" for s, c in compute.items())
    targets.append(["Issue 20: dynamics service round trips ≤ 1.3× a same-size echo, K = 1000 with derivatives",
                    f"{worst[1000]:.3g}×", verdict(worst[1000] <= 1.3, "" if worst[1000] <= 1.3 else
                                                   f"the node's computation per configuration ({per}) "
                                                   "is more than the echo's copy")])
    return ["", "### Dynamics services against a same-size echo", "",
            "One free body of the scene (6 coordinates), random states with |θ| ≤ 1; "
            "`SceneQueries::inverseDynamics` / `forwardDynamics`, the node's code path.",
            "", md_table(["call", "payload", "service", "echo", "÷ echo"], rows)]


def section_scene(scene):
    rows = []
    for s in scene["scenes"]:
        sink = s["tf_sink"]
        rate = sink["messages"] / sink["seconds"] if sink["seconds"] else 0
        rows.append([f"{s['bodies']:,}", "the node itself (load, tf and ~states publication)", f"{s['log_line_s']:.2f} s", f"{s['services_ready_s']:.2f} s",
                     f"{s['vm_rss_bytes'] / 2**20:.1f} MiB", f"{100 * s['cpu_no_subscriber']:.1f} %",
                     f"{100 * s['cpu_one_subscriber']:.1f} %", f"{rate:.1f} Hz"])
    return "\n".join(["## 6. Scene scale", "",
                      "Generated URDFs of boxes on floating joints; the node with `~publish_rate` 50 Hz. Load: from "
                      "process start to the node's 'serving' log line (written once its services are advertised), and to "
                      "its services being registered. "
                      f"CPU: the node's utime + stime from /proc/<pid>/stat over {scene['cpu_window_s']:.0f} s, in "
                      "% of one core, with no tf subscriber and with one C++ subscriber to /tf (its received rate "
                      "in the last column).", "",
                      md_table(["bodies", "node runs", "loaded", "services ready", "VmRSS", "CPU, no subscriber",
                                "CPU, one /tf subscriber", "tf received"], rows)])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--results", required=True)
    parser.add_argument("--docs", required=True)
    parser.add_argument("--workspace", required=True)
    parser.add_argument("--repo", required=True)
    parser.add_argument("--seconds", type=float, default=None, help="wall time of the whole run")
    parser.add_argument("--analysis", default=None, help="markdown appended as the analysis section")
    args = parser.parse_args()
    os.makedirs(args.docs, exist_ok=True)
    kernels_json = load(os.path.join(args.results, "kernels.json"))
    k = kernel_table(kernels_json)
    acc = load(os.path.join(args.results, "accuracy.json"))
    targets = []
    parts = []
    floor_rows = []
    parts.append(section_mass_matrix(k, acc, targets))
    parts.append(section_jacobians(k, acc, targets, floor_rows))
    parts.append(section_backprop(k, acc, targets, floor_rows))
    parts.append(section_floors(floor_rows))
    inertia_path = os.path.join(args.results, "inertia.json")
    if os.path.exists(inertia_path):
        parts.append(section_inertia(load(inertia_path), args.docs))
    service_path = os.path.join(args.results, "service.json")
    if os.path.exists(service_path):
        parts.append(section_service(load(service_path), targets))
    scene_path = os.path.join(args.results, "scene.json")
    if os.path.exists(scene_path):
        parts.append(section_scene(load(scene_path)))
    articulated_path = os.path.join(args.results, "articulated.json")  # drb_bench_articulated
    if os.path.exists(articulated_path):
        parts.append(section_articulated(load(articulated_path), targets))
    gimbal_path = os.path.join(args.results, "gimbal.json")  # drb_bench_gimbal
    if os.path.exists(gimbal_path):
        parts.append(section_gimbal(load(gimbal_path), targets))
    client_path = os.path.join(args.results, "client_trajectory.md")  # written by bench/client_trajectory.py
    if os.path.exists(client_path):
        parts.append(open(client_path).read().strip())
    pool_path = os.path.join(args.results, "pool.md")  # written by bench/pool_throughput.py
    if os.path.exists(pool_path):
        parts.append(open(pool_path).read().strip())
    local = section_local(args.results, targets)  # local.json (bench/local_throughput.py), local_kernels.json
    if local:
        parts.append(local)
    plot_kernels(k, acc, args.docs)

    info = machine(args.workspace, kernels_json, args.repo, args.results)
    repetitions = max((b.get("repetitions", 1) for b in kernels_json["benchmarks"]), default=1)
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    head = ["# Benchmarks: speed against error",
            "",
            f"Generated by `scripts/bench` on {now}"
            + (f" in {args.seconds / 60:.1f} min" if args.seconds else "") + "; do not edit by hand "
            "(the analysis at the end comes from `bench/analysis.md`). Reproduce with",
            "",
            "```bash",
            "./scripts/bench            # DRB_WORKSPACE=/path/to/ws to build elsewhere",
            "```",
            "",
            "Every figure is measured in the same run as the peers it is compared with: KDL "
            "(`liborocos-kdl-dev`), MuJoCo (`libmujoco-dev`) and, for bodies with joints, Pinocchio 3.7.0 "
            "(vendored in bench/third_party). Kernel times are medians over "
            f"{repetitions} repetitions, run in random interleaved order (a slow phase of the machine "
            "lands on every method alike), of Google Benchmark's **CPU time** per operation (robust on a shared machine; the JSON in the "
            "results folder also has wall time). Errors are maxima of the relative error against a 256-bit "
            "MPFR reference (our scalar-templated kernels evaluated in `mpfr::mpreal`) over the hard cases of "
            "docs/derivation.md (\"Hard cases\"): random states, gimbal lock θ = ±π/2 and ±π/2 ± 10⁻ᵏ (k = 1…16), angles up to 1e6 rad, "
            "masses 1e-9 … 1e9 kg, thin rods I = diag(1e-9, 1, 1), vertices 1e-6 … 1e4 m from the COM. "
            "ε = 2⁻⁵² ≈ 2.2e-16.",
            "",
            "![kernels: time against error](benchmarks_kernels.png)",
            "",
            "## Machine",
            "",
            md_table(["", ""], [[key, value] for key, value in info.items()]),
            "",
            "## Targets",
            "",
            md_table(["target", "measured", "verdict"], targets)]
    body = "\n\n".join(parts)
    analysis = ""
    if args.analysis and os.path.exists(args.analysis):
        analysis = "\n\n" + open(args.analysis).read().strip() + "\n"
    with open(os.path.join(args.docs, "benchmarks.md"), "w") as f:
        f.write("\n".join(head) + "\n\n" + body + analysis + "\n")
    print(os.path.join(args.docs, "benchmarks.md"))


if __name__ == "__main__":
    main()
