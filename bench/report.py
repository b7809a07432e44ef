#!/usr/bin/python3
"""Turns the JSON written by the benchmark binaries into docs/benchmarks.md and
the PNG plots beside it. Run by scripts/bench (Debian's python3, numpy,
matplotlib).

  report.py --results DIR --docs DIR --workspace WS --repo REPO
"""
import argparse
import datetime
import json
import math
import os
import platform
import re
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

EPS = 2.0 ** -52  # double epsilon: errors are also given in units of it

# ---------------------------------------------------------------------------
# Loading.


def load(path):
    with open(path) as f:
        return json.load(f)


def kernel_table(kernels):
    """run name -> {'cpu': ns per item, 'real': ns per item, 'items': n} from the medians."""
    table = {}
    for b in kernels["benchmarks"]:
        if b.get("run_type") != "aggregate" or b.get("aggregate_name") != "median":
            continue
        name = re.sub(r"/min_time:[0-9.]+|/real_time$", "", b["run_name"])
        items = b.get("items", 1.0)
        scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[b.get("time_unit", "ns")]
        table[name] = {"cpu": b["cpu_time"] * scale / items, "real": b["real_time"] * scale / items, "items": items}
    return table


def max_error(errors, method, exclude_prefix=None):
    tags = errors.get(method)
    if not tags:
        return None
    values = [v for k, v in tags.items() if k != "all" and not (exclude_prefix and k.startswith(exclude_prefix))]
    return max(values) if values else None


# ---------------------------------------------------------------------------
# Formatting.


def fmt_time(ns):
    if ns is None:
        return "n/a"
    if ns >= 1e6:
        return f"{ns / 1e6:.3g} ms"
    if ns >= 1e3:
        return f"{ns / 1e3:.3g} µs"
    if ns >= 10:
        return f"{ns:.0f} ns"
    return f"{ns:.2g} ns"


def fmt_ratio(x):
    if x is None or not math.isfinite(x):
        return "n/a"
    return f"{x:.3g}×" if x < 100 else f"{x:.0f}×"


def fmt_err(e):
    if e is None:
        return "n/a"
    if e == 0:
        return "0"
    if e < 1e-13:
        return f"{e:.2g} ({e / EPS:.2g} ε)"
    return f"{e:.2g}"


def md_table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(str(c) for c in r) + " |")
    return "\n".join(lines)


def verdict(ok, text):
    return ("**met**" if ok else "**missed**") + (" — " + text if text else "")


# ---------------------------------------------------------------------------
# Machine.


def run(argv):
    try:
        return subprocess.run(argv, capture_output=True, text=True, timeout=20).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def machine(workspace, kernels, repo):
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
    commit = run(["git", "-C", repo, "rev-parse", "--short", "HEAD"])
    dirty = run(["git", "-C", repo, "status", "--porcelain", "--untracked-files=no"])
    info["source"] = commit + (" + uncommitted changes" if dirty else "")
    return info


# ---------------------------------------------------------------------------
# Sections.


def section_mass_matrix(k, acc, targets):
    errors = acc["mass_matrix"]
    kdl = k.get("mass_matrix/kdl", {}).get("cpu")
    mj = k.get("mass_matrix/mujoco", {}).get("cpu")
    rows = []
    methods = [("ours_double", "ours, double", "ours_double"), ("ours_float", "ours, float", "ours_float"),
               ("kdl", "KDL ChainDynParam::JntToMass", "kdl"),
               ("mujoco", "MuJoCo mj_kinematics + mj_comPos + mj_crb + mj_fullM", "mujoco"),
               ("mujoco_fwdPosition", "MuJoCo mj_fwdPosition + mj_fullM", "mujoco"),
               ("fd_energy", "finite differences of kinetic energy", "fd_energy")]
    for key, label, err_key in methods:
        t = k.get("mass_matrix/" + key, {}).get("cpu")
        if t is None:
            continue
        rows.append([label, fmt_time(t), fmt_ratio(kdl / t) if kdl else "n/a", fmt_ratio(mj / t) if mj else "n/a",
                     fmt_err(max_error(errors, err_key)), fmt_err(max_error(errors, err_key, "large_angle"))])
    text = ["## 1. Mass matrix, one body, one state per call",
            "",
            "Angles change from call to call (256 states cycled, one in eight a hard case), so no trigonometry "
            "can be hoisted. Ratios are the peer's time over the method's (> 1: the method is faster).",
            "",
            md_table(["method", "time / matrix", "vs KDL", "vs MuJoCo", "max rel. error", "… with |angles| ≤ π"],
                     rows)]
    # Batched.
    brows = []
    mjb = k.get("mass_matrix_batch/mujoco/64", {}).get("cpu")
    for K in (8, 64, 1024):
        t = k.get(f"mass_matrix_batch/ours_double/{K}", {}).get("cpu")
        if t is None:
            continue
        brows.append([f"ours, massMatrixBatch, K = {K}", fmt_time(t), fmt_ratio(kdl / t) if kdl else "n/a",
                      fmt_ratio(mjb / t) if mjb else "n/a", fmt_err(max_error(errors, "ours_batch_double"))])
    if mjb:
        brows.append(["MuJoCo, K = 64 calls (no batched API)", fmt_time(mjb), fmt_ratio(kdl / mjb) if kdl else "n/a",
                      "1×", fmt_err(max_error(errors, "mujoco"))])
    text += ["", "### Batched mass matrices", "",
             "`massMatrixBatch` (mass_matrix.h): K states of one body; sines and cosines of a block of 8 states "
             "at once by a branch-free Cody-Waite + minimax-polynomial `sinCos` (rpy.h) that the compiler "
             "vectorises at the baseline ISA (SSE2, no -march flag); M written straight to the row-major "
             "output. Ratio columns against KDL's single call and MuJoCo's 64 calls.",
             "",
             md_table(["method", "time / matrix", "vs KDL", "vs MuJoCo", "max rel. error"], brows)]
    trig = acc.get("sincos_abs", {})
    if trig:
        text += ["", f"Absolute error of the vectorised `sinCos` over the state set and 4096 random angles up to "
                     f"1e6 rad: {fmt_err(trig['sinCos']['all'])} (glibc's sin/cos: {fmt_err(trig['std']['all'])})."]
    # Targets.
    t_single = k.get("mass_matrix/ours_double", {}).get("cpu")
    if t_single and kdl:
        r = kdl / t_single
        targets.append(["single M ≥ 20× faster than KDL", fmt_ratio(r), verdict(r >= 20, "")])
    if t_single and mj:
        r = mj / t_single
        targets.append(["single M ≥ 10× faster than MuJoCo", fmt_ratio(r), verdict(r >= 10, "")])
    t64 = k.get("mass_matrix_batch/ours_double/64", {}).get("cpu")
    if t64 and mjb:
        r = mjb / t64
        targets.append(["batched M (K = 64) ≥ 20× faster per matrix than MuJoCo", fmt_ratio(r),
                        verdict(r >= 20, "" if r >= 20 else f"short by {20 / r:.2g}×")])
    e = max_error(errors, "ours_double")
    eb = max_error(errors, "ours_batch_double")
    if e is not None and eb is not None:
        worst = max(e, eb)
        targets.append(["errors stay at a few ulp in double (M, single and batched)",
                        f"{worst / EPS:.2g} ε", verdict(worst <= 8 * EPS, "")])
    return "\n".join(text)


JAC_METHODS = [("ours_double", "ours, double (J only, 144 B/vertex)", "ours_double"),
               ("ours_double_with_positions", "ours, double, positions + J (168 B/vertex)", "ours_double"),
               ("ours_float", "ours, float (72 B/vertex)", "ours_float"),
               ("ours_rotation_block_double", "ours, rotation block only (72 B/vertex)",
                "ours_rotation_block_double"),
               ("kdl", "KDL ChainJntToJacSolver + changeRefPoint", "kdl"),
               ("mujoco", "MuJoCo mj_jac", "mujoco"),
               ("central_diff", "central differences", "central_diff"),
               ("complex_step", "complex step", "complex_step"),
               ("memcpy_144B", "memcpy of 144 B/vertex (floor for J)", None),
               ("memcpy_168B", "memcpy of 168 B/vertex (floor for positions + J)", None),
               ("memcpy_72B", "memcpy of 72 B/vertex (floor for float J)", None)]


def vertex_sets(k):
    sets = []
    for name in k:
        m = re.match(r"jacobian/([^/]+)/ours_double$", name)
        if m:
            sets.append((k[name]["items"], m.group(1)))
    return [s for _, s in sorted(sets)]


def section_jacobians(k, acc, targets):
    errors = acc["jacobian"]
    text = ["## 2. Vertex Jacobians",
            "",
            "Time per vertex for a whole mesh per call (the state changes every call). J is 3×6 row-major "
            "(18 doubles = 144 B). KDL: the chain Jacobian once per body, then `changeRefPoint` per vertex; "
            "MuJoCo: `mj_kinematics` + `mj_comPos` once per body, then `mj_jac` per vertex. Errors are over "
            "the whole state set and vertices from 1e-6 m to 1e4 m (`max|ΔJr|/max|Jr|`, Jr the rotation block).",
            ""]
    for s in vertex_sets(k):
        items = int(k[f"jacobian/{s}/ours_double"]["items"])
        floor = k.get(f"jacobian/{s}/memcpy_144B", {}).get("cpu")
        kdl = k.get(f"jacobian/{s}/kdl", {}).get("cpu")
        mj = k.get(f"jacobian/{s}/mujoco", {}).get("cpu")
        rows = []
        for key, label, err_key in JAC_METHODS:
            t = k.get(f"jacobian/{s}/{key}", {}).get("cpu")
            if t is None:
                continue
            rows.append([label, fmt_time(t), fmt_ratio(t / floor) if floor else "n/a",
                         fmt_ratio(kdl / t) if kdl else "n/a", fmt_ratio(mj / t) if mj else "n/a",
                         fmt_err(max_error(errors, err_key)) if err_key else "—"])
        text += [f"### {s} ({items:,} vertices)", "",
                 md_table(["method", "time / vertex", "÷ memcpy 144 B", "vs KDL", "vs MuJoCo", "max rel. error"],
                          rows), ""]
    big = [s for s in vertex_sets(k) if k[f"jacobian/{s}/ours_double"]["items"] >= 5e5]
    if big:
        s = big[-1]
        t = k[f"jacobian/{s}/ours_double"]["cpu"]
        floor = k.get(f"jacobian/{s}/memcpy_144B", {}).get("cpu")
        if floor:
            r = t / floor
            targets.append([f"vertex Jacobians within 1.25× of memcpy (same bytes) at 10^6 vertices", f"{r:.3g}×",
                            verdict(r <= 1.25, "" if r <= 1.25 else f"over by {r / 1.25:.2g}×")])
    e = max_error(errors, "ours_double")
    if e is not None:
        targets.append(["J error at a few ulp in double", f"{e / EPS:.2g} ε", verdict(e <= 8 * EPS, "")])
    return "\n".join(text)


def section_backprop(k, acc, targets):
    errors = acc["backprop"]
    pose = k.get("backprop_fixed/body_pose", {}).get("cpu")
    text = ["## 3. Backprop (vector-Jacobian product)",
            "",
            "dL/dq = Σ J_iᵀ g_i. Ours never forms J: W = Σ g_i p0_iᵀ and Σ g_i, then one 3×3 product "
            "(`backpropFromSums`). **By coordinate** (`vertex_columns.h`, what the node runs for a request of all "
            "vertices): the body's vertices are kept as x, y, z arrays made once at load (24 B per vertex), so one "
            "load holds 8 vertices' x (AVX-512) or 4 (AVX2 + FMA), chosen at run time; only the client's gradients are "
            "transposed in registers. **As stored** (3×N, `vertex_jacobian.h`, used for index lists): both "
            "operands transposed, 4 vertices per AVX2 register. **2 threads**: the by-coordinate sum cut into two "
            "contiguous chunks (only for ≥ 2 × 65,536 vertices; wall time, since CPU time counts one thread). "
            "Baselines: J formed per vertex in registers and multiplied; and J written for all vertices (as "
            "`get_vertex_jacobians` returns it) then multiplied. Times per vertex, each call over the whole set at a "
            "new state. Errors relative to the sum of the terms' magnitudes (Σ|p0_i||g_i| for dL/dr, Σ|g_i| for "
            "dL/dt).",
            ""]
    rows = []
    ratios = []
    for s in vertex_sets(k):
        t = k.get(f"backprop/{s}/ours_columns", {}).get("cpu")
        if t is None:
            continue
        t2 = k.get(f"backprop/{s}/ours_columns_2_threads", {}).get("real")
        t_aos = k.get(f"backprop/{s}/ours_double", {}).get("cpu")
        f = k.get(f"backprop/{s}/form_J_and_multiply", {}).get("cpu")
        b = k.get(f"backprop/{s}/J_buffer_then_multiply", {}).get("cpu")
        items = int(k[f"backprop/{s}/ours_columns"]["items"])
        rows.append([f"{s} ({items:,})", fmt_time(t), fmt_time(t2) if t2 else "n/a",
                     fmt_time(t_aos) if t_aos else "n/a", fmt_time(f), fmt_ratio(f / t) if f else "n/a",
                     fmt_time(b), fmt_ratio(b / t) if b else "n/a"])
        ratios.append((s, items, f / t if f else None, b / t if b else None, b * items if b else None))
    text.append(md_table(["vertex set", "ours, by coordinate", "… 2 threads (wall)", "ours, as stored (3×N)",
                          "J in registers, multiply", "speed-up", "J buffer, then multiply", "speed-up"], rows))
    text += ["", "Max rel. error: ours by coordinate " + fmt_err(max_error(errors, "ours_columns")) +
             ", as stored " + fmt_err(max_error(errors, "ours_double")) + ", J in registers " +
             fmt_err(max_error(errors, "form_J_and_multiply")) + ", J buffer " +
             fmt_err(max_error(errors, "J_buffer_then_multiply")) + "."]
    fixed = k.get("backprop_fixed/ours_columns_no_vertices", {}).get("cpu")
    if pose and fixed:
        text += ["", f"Per call, beyond its vertices, ours costs {fmt_time(fixed)} (a call with no vertex): the "
                 f"pose q → R, T (`BodyPose`, three sin/cos pairs, {fmt_time(pose)}, which the baselines pay too), "
                 "the SIMD set-up and lane reductions, and dL/dq from the sums. However fast the per-vertex loop, a "
                 "call's speed-up cannot exceed (baseline's call) ÷ (this fixed part):"]
        bounds = [[f"{s} ({items:,})", fmt_time(call), fmt_ratio(call / fixed)]
                  for s, items, _, _, call in ratios if call and call / fixed < 1000]
        if bounds:
            text += ["", md_table(["vertex set", "J buffer, then multiply, per call",
                                   "speed-up bound from ours' fixed part"], bounds)]
    for s, items, regs, buf, _ in ratios:
        if regs is None or buf is None:
            continue
        if regs >= 10:
            v = verdict(True, "against both baselines")
        elif buf >= 10:
            v = verdict(True, f"against the J buffer; against J in registers short by {10 / regs:.2g}×")
        else:
            v = verdict(False, f"short by {10 / buf:.2g}× (J buffer), {10 / regs:.2g}× (J in registers)")
        targets.append([f"backprop ≥ 10× faster per vertex than forming J and multiplying, {s} ({items:,})",
                        f"{fmt_ratio(buf)} (J buffer), {fmt_ratio(regs)} (registers)", v])
    return "\n".join(text)


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
            rows.append([mesh["name"], f"{p['samples']:,}", fmt_time(p["seconds"] * 1e9), f"{p['mass_error']:.2g}",
                         f"{p['com_error']:.2g}", f"{p['inertia_error']:.2g}"])
        rows.append([mesh["name"], "exact (meshMassProperties)", fmt_time(mesh["exact_seconds"] * 1e9), "—", "—",
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
             md_table(["mesh", "samples", "time", "mass error", "COM error", "inertia error"], rows)]
    return "\n".join(text)


def plot_kernels(k, acc, docs):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    labels = {"ours_double": "ours double", "ours_float": "ours float", "kdl": "KDL", "mujoco": "MuJoCo",
              "fd_energy": "FD of energy", "central_diff": "central diff.", "complex_step": "complex step",
              "ours_batch_double": "ours batched (K=64)"}
    ax = axes[0]
    for key in ("ours_double", "ours_float", "kdl", "mujoco", "fd_energy", "ours_batch_double"):
        name = "mass_matrix_batch/ours_double/64" if key == "ours_batch_double" else "mass_matrix/" + key
        t = k.get(name, {}).get("cpu")
        e = max_error(acc["mass_matrix"], key, "large_angle" if key == "ours_float" else None)
        if t is None or e is None:
            continue
        ax.loglog(max(e, 1e-17), t, "o")
        ax.annotate(labels[key], (max(e, 1e-17), t), fontsize=8, textcoords="offset points", xytext=(5, 3))
    ax.set_title("mass matrix (one body)")
    ax.set_xlabel("max relative error vs MPFR-256")
    ax.set_ylabel("time per matrix [ns]")
    ax.grid(True, which="both", alpha=0.3)
    ax = axes[1]
    sets = vertex_sets(k)
    s = next((x for x in sets if "bunny" in x), sets[0] if sets else None)
    if s:
        for key in ("ours_double", "ours_float", "kdl", "mujoco", "central_diff", "complex_step"):
            t = k.get(f"jacobian/{s}/{key}", {}).get("cpu")
            e = max_error(acc["jacobian"], key, "large_angle" if key == "ours_float" else None)
            if t is None or e is None:
                continue
            ax.loglog(max(e, 1e-17), t, "o")
            ax.annotate(labels[key], (max(e, 1e-17), t), fontsize=8, textcoords="offset points", xytext=(5, 3))
        floor = k.get(f"jacobian/{s}/memcpy_144B", {}).get("cpu")
        if floor:
            ax.axhline(floor, linestyle="--", color="gray", linewidth=0.8, label="memcpy of 144 B")
            ax.legend(fontsize=8)
        ax.set_title(f"vertex Jacobians ({s})")
        ax.set_xlabel("max relative error vs MPFR-256")
        ax.set_ylabel("time per vertex [ns]")
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle("Kernels: speed against error (float: |angles| ≤ π; its error at 1e6 rad is the input's rounding)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(docs, "benchmarks_kernels.png"), dpi=120)
    plt.close(fig)


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
    for name, label in (("ping", "~ping (empty)"), ("get_mass_matrix", "~get_mass_matrix, 1 matrix"),
                        ("ping_nodelay", "~ping, client sockets with TCP_NODELAY"),
                        ("get_mass_matrix_nodelay", "~get_mass_matrix, client sockets with TCP_NODELAY"),
                        ("get_mass_matrix_K1000", "~get_mass_matrix, K = 1000 configurations"),
                        ("echo_for_get_mass_matrix_K1000", "~echo, same bytes as K = 1000")):
        x = t.get(name)
        if x:
            rows.append([label, f"{us(x['median_s'])} [{us(x['p25_s'])}, {us(x['p75_s'])}]", x["calls"],
                         fmt_ratio(x["median_s"] / ping["median_s"]) if ping else "n/a"])
    text.append(md_table(["call", "round trip", "calls", "÷ ~ping"], rows))
    if ping and mm:
        r = mm["median_s"] / ping["median_s"]
        targets.append(["get_mass_matrix round trip ≤ 1.3× the empty service", f"{r:.3g}×",
                        verdict(r <= 1.3, "" if r <= 1.3 else f"over by {r / 1.3:.2g}×")])
    # Vertex services.
    rows = []
    worst = {"get_vertex_jacobians": 0, "backprop": 0}
    sizes = sorted({int(n.split("/")[1]) for n in t if n.startswith("get_vertex_jacobians/")})
    for n in sizes:
        for svc, label in (("get_vertex_jacobians", "get_vertex_jacobians"), ("compact_rotation_block", "compact: rotation block"),
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
            rows.append([f"{n:,}", label, f"{nbytes / 1e6:.3g} MB", us(x["median_s"]), us(e["median_s"]),
                         fmt_ratio(r), f"{nbytes / x['median_s'] / 1e9:.2g} GB/s", err])
    text += ["", "### Vertex services against a same-size echo", "",
             md_table(["vertices", "service", "payload", "service", "echo", "÷ echo", "payload rate",
                       "reduced transport error vs full answer"], rows)]
    for svc in ("get_vertex_jacobians", "backprop"):
        if worst[svc]:
            r = worst[svc]
            targets.append([f"{svc} ≤ 1.5× the same-size echo (worst size)", f"{r:.3g}×",
                            verdict(r <= 1.5, "" if r <= 1.5 else f"over by {r / 1.5:.2g}×")])
    return "\n".join(text)


def section_scene(scene):
    rows = []
    for s in scene["scenes"]:
        sink = s["tf_sink"]
        rate = sink["messages"] / sink["seconds"] if sink["seconds"] else 0
        rows.append([f"{s['bodies']:,}", f"{s['log_line_s']:.2f} s", f"{s['services_ready_s']:.2f} s",
                     f"{s['vm_rss_bytes'] / 2**20:.1f} MiB", f"{100 * s['cpu_no_subscriber']:.1f} %",
                     f"{100 * s['cpu_one_subscriber']:.1f} %", f"{rate:.1f} Hz"])
    return "\n".join(["## 6. Scene scale", "",
                      "Generated URDFs of boxes on floating joints; the node with `~publish_rate` 50 Hz. Load: from "
                      "process start to the node's 'serving' log line, and to its services being registered. "
                      f"CPU: the node's utime + stime from /proc/<pid>/stat over {scene['cpu_window_s']:.0f} s, in "
                      "% of one core, with no tf subscriber and with one C++ subscriber to /tf (its received rate "
                      "in the last column).", "",
                      md_table(["bodies", "loaded", "services ready", "VmRSS", "CPU, no subscriber",
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
    parts.append(section_mass_matrix(k, acc, targets))
    parts.append(section_jacobians(k, acc, targets))
    parts.append(section_backprop(k, acc, targets))
    inertia_path = os.path.join(args.results, "inertia.json")
    if os.path.exists(inertia_path):
        parts.append(section_inertia(load(inertia_path), args.docs))
    service_path = os.path.join(args.results, "service.json")
    if os.path.exists(service_path):
        parts.append(section_service(load(service_path), targets))
    scene_path = os.path.join(args.results, "scene.json")
    if os.path.exists(scene_path):
        parts.append(section_scene(load(scene_path)))
    plot_kernels(k, acc, args.docs)

    info = machine(args.workspace, kernels_json, args.repo)
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
            "(`liborocos-kdl-dev`) and MuJoCo (`libmujoco-dev`). Kernel times are medians over "
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
