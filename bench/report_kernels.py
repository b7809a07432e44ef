"""Sections 1-3 of docs/benchmarks.md (mass matrix, vertex Jacobians, backprop)
and the kernel plot, from drb_bench_kernels' and drb_bench_accuracy's JSON.
Every row names the function the node runs for it, or says that the node
never runs it (a peer, a reference or a memory floor)."""
import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from report_format import (EPS, FLOOR, NOT_NODE, PEER, fmt_err, fmt_ratio, fmt_time, max_error,  # noqa: E402
                           md_table, verdict)

PATHS = (("avx512", "AVX-512F"), ("avx2", "AVX2 + FMA"), ("sse2", "SSE2"))
NODE_BATCH = "yes: `SceneQueries::massMatrices` → `massMatrices` → `massMatrixBatch` (free object)"


def cpu(k, name):
    return k.get(name, {}).get("cpu")


def row_against(k, t, kdl, mj):
    return [fmt_ratio(kdl / t) if kdl else "n/a", fmt_ratio(mj / t) if mj else "n/a"]


def section_mass_matrix(k, acc, targets):
    errors = acc["mass_matrix"]
    kdl, mj = cpu(k, "mass_matrix/kdl"), cpu(k, "mass_matrix/mujoco")
    methods = [("mass_matrix_batch/ours_double/1", "ours, `massMatrixBatch` of 1 state", "ours_batch_single",
                NODE_BATCH + " (a request of one state per body)"),
               ("mass_matrix_node/1_body/1", "ours, `SceneQueries::massMatrices`, 1 matrix (whole call)",
                "ours_batch_single", "yes: the node's whole call (checks, answer vectors, kernel)"),
               ("mass_matrix/ours_double", "ours, `massMatrix(q)`, double", "ours_double", NOT_NODE),
               ("mass_matrix/ours_float", "ours, `massMatrix(q)`, float", "ours_float", NOT_NODE),
               ("mass_matrix/kdl", "KDL ChainDynParam::JntToMass", "kdl", PEER),
               ("mass_matrix/mujoco", "MuJoCo mj_kinematics + mj_comPos + mj_crb + mj_fullM", "mujoco", PEER),
               ("mass_matrix/mujoco_fwdPosition", "MuJoCo mj_fwdPosition + mj_fullM", "mujoco", PEER),
               ("mass_matrix/fd_energy", "finite differences of kinetic energy", "fd_energy", NOT_NODE)]
    rows = []
    for key, label, err_key, node in methods:
        t = cpu(k, key)
        if t is None:
            continue
        rows.append([label, node, fmt_time(t)] + row_against(k, t, kdl, mj) +
                    [fmt_err(max_error(errors, err_key)), fmt_err(max_error(errors, err_key, "large_angle"))])
    text = ["## 1. Mass matrix, one body, one state per call",
            "",
            "Angles change from call to call (256 states cycled, one in eight a hard case), so no trigonometry "
            "can be hoisted. Ratios are the peer's time over the method's (> 1: the method is faster). The node "
            "runs `massMatrixBatch` for every `get_mass_matrix` request; for one state it takes glibc's "
            "sin/cos (the vectorised `sinCos` needs a block of 8 states), which is also what makes its "
            "`cos_theta` equal `std::cos(theta)` bit for bit.",
            "",
            md_table(["method", "node runs", "time / matrix", "vs KDL", "vs MuJoCo", "max rel. error",
                      "… with |angles| ≤ π"], rows)]
    brows = []
    mjb = cpu(k, "mass_matrix_batch/mujoco/64")
    batch = [(f"mass_matrix_batch/ours_double/{K}", f"ours, `massMatrixBatch`, K = {K}",
              NODE_BATCH + f" (one body, {K} configurations)") for K in (8, 64, 1024)]
    batch += [("mass_matrix_node/1_body/64", "ours, `SceneQueries::massMatrices`, 1 body, K = 64 (whole call)",
               "yes: the node's whole call"),
              ("mass_matrix_node/2_bodies/64", "ours, `SceneQueries::massMatrices`, 2 bodies, K = 64 (whole call)",
               "yes: the node's whole call (`massMatrixBatch` per body through an L1 block)")]
    for key, label, node in batch:
        t = cpu(k, key)
        if t is not None:
            brows.append([label, node, fmt_time(t)] + row_against(k, t, kdl, mjb) +
                         [fmt_err(max_error(errors, "ours_batch_double"))])
    if mjb:
        brows.append(["MuJoCo, K = 64 calls (no batched API)", PEER, fmt_time(mjb),
                      fmt_ratio(kdl / mjb) if kdl else "n/a", "1×", fmt_err(max_error(errors, "mujoco"))])
    text += ["", "### Batched mass matrices", "",
             "`massMatrixBatch` (mass_matrix.h): K states of one body; sines and cosines of a block of 8 states "
             "at once by a branch-free Cody-Waite + minimax-polynomial `sinCos` that the compiler "
             "vectorises at the baseline ISA (SSE2, no -march flag); M written straight to the row-major "
             "output. Times per matrix; ratio columns against KDL's single call and MuJoCo's 64 calls.",
             "",
             md_table(["method", "node runs", "time / matrix", "vs KDL", "vs MuJoCo", "max rel. error"], brows)]
    trig = acc.get("sincos_abs", {})
    if trig:
        text += ["", f"Absolute error of the vectorised `sinCos` over the state set and 4096 random angles up to "
                     f"1e6 rad: {fmt_err(trig['sinCos']['all'])} (glibc's sin/cos: {fmt_err(trig['std']['all'])})."]
    t_single = cpu(k, "mass_matrix_batch/ours_double/1")
    if t_single and kdl:
        r = kdl / t_single
        targets.append(["single M ≥ 20× faster than KDL (the node's kernel)", fmt_ratio(r), verdict(r >= 20, "")])
    if t_single and mj:
        r = mj / t_single
        targets.append(["single M ≥ 10× faster than MuJoCo (the node's kernel)", fmt_ratio(r), verdict(r >= 10, "")])
    t64 = cpu(k, "mass_matrix_batch/ours_double/64")
    if t64 and mjb:
        r = mjb / t64
        targets.append(["batched M (K = 64) ≥ 20× faster per matrix than MuJoCo", fmt_ratio(r),
                        verdict(r >= 20, "" if r >= 20 else f"short by {20 / r:.2g}×")])
    es = [max_error(errors, key) for key in ("ours_batch_single", "ours_batch_double")]
    if None not in es:
        worst = max(es)
        targets.append(["errors stay at a few ulp in double (M, single and batched)",
                        f"{worst / EPS:.2g} ε", verdict(worst <= 8 * EPS, "")])
    return "\n".join(text)


NODE_J = ("yes: `SceneQueries::vertexJacobians` → `vertexJacobians` → `vertexPositionsAndJacobians` (free object; "
          "SSE2, the only path)")
JAC_METHODS = [
    ("node_positions_and_J", "ours, positions + J (168 B/vertex)", "ours_double", NODE_J),
    ("node_compact_rotation_block", "ours, positions + rotation block (96 B/vertex)", "ours_rotation_block_double",
     "yes: `SceneQueries::vertexRotationJacobians<double>` (compact service)"),
    ("node_compact_rotation_block_float32", "ours, positions + rotation block, float32 (48 B/vertex)",
     "ours_rotation_block_float32_transport", "yes: `SceneQueries::vertexRotationJacobians<float>` (compact service)"),
    ("ours_double", "ours, J only (144 B/vertex)", "ours_double", NOT_NODE),
    ("ours_float", "ours, float kernel (72 B/vertex)", "ours_float", NOT_NODE),
    ("kdl", "KDL ChainJntToJacSolver + changeRefPoint", "kdl", PEER),
    ("mujoco", "MuJoCo mj_jac", "mujoco", PEER),
    ("central_diff", "central differences", "central_diff", NOT_NODE),
    ("complex_step", "complex step", "complex_step", NOT_NODE)]
JAC_FLOORS = [(f"floor_write_168B_{p}", f"write floor, 168 B/vertex, {name} stores") for p, name in PATHS]
JAC_FLOORS.append(("memcpy_168B", "memcpy of 168 B/vertex"))


def vertex_sets(k):
    sets = []
    for name in k:
        m = re.match(r"jacobian/([^/]+)/node_positions_and_J$", name)
        if m:
            sets.append((k[name]["items"], m.group(1)))
    return [s for _, s in sorted(sets)]


def floors(k, prefix, kind):
    """path -> floor time per vertex for the paths measured."""
    return {p: cpu(k, f"{prefix}/floor_{kind}_{p}") for p, _ in PATHS if cpu(k, f"{prefix}/floor_{kind}_{p}")}


def section_jacobians(k, acc, targets, floor_rows):
    errors = acc["jacobian"]
    text = ["## 2. Vertex Jacobians",
            "",
            "Time per vertex for a whole mesh per call (the state changes every call). J is 3×6 row-major "
            "(18 doubles = 144 B); the node returns positions too (168 B per vertex). KDL: the chain Jacobian once "
            "per body, then `changeRefPoint` per vertex; MuJoCo: `mj_kinematics` + `mj_comPos` once per body, then "
            "`mj_jac` per vertex. **Write floor**: the same 168 B per vertex written once into the same arrays by a "
            "plain store loop at each SIMD width, with the kernel's kind of store (ordinary, or non-temporal from "
            "16 MiB of J); `÷ floor` is against the fastest of them. Errors are over the whole state set and "
            "vertices from 1e-6 m to 1e4 m (`max|ΔJr|/max|Jr|`, Jr the rotation block).",
            ""]
    for s in vertex_sets(k):
        prefix = f"jacobian/{s}"
        items = int(k[f"{prefix}/node_positions_and_J"]["items"])
        fl = floors(k, prefix, "write_168B")
        best = min(fl.values()) if fl else None
        kdl, mj = cpu(k, f"{prefix}/kdl"), cpu(k, f"{prefix}/mujoco")
        rows = []
        for key, label, err_key, node in JAC_METHODS:
            t = cpu(k, f"{prefix}/{key}")
            if t is None:
                continue
            ratio = fmt_ratio(t / best) if best and key == "node_positions_and_J" else "—"
            rows.append([label, node, fmt_time(t), ratio] + row_against(k, t, kdl, mj) +
                        [fmt_err(max_error(errors, err_key))])
        for key, label in JAC_FLOORS:
            t = cpu(k, f"{prefix}/{key}")
            if t is not None:
                rows.append([label, FLOOR, fmt_time(t), fmt_ratio(t / best) if best else "n/a"] +
                            row_against(k, t, kdl, mj) + ["—"])
        text += [f"### {s} ({items:,} vertices)", "",
                 md_table(["method", "node runs", "time / vertex", "÷ write floor", "vs KDL", "vs MuJoCo",
                           "max rel. error"], rows), ""]
        t = cpu(k, f"{prefix}/node_positions_and_J")
        if t and fl:
            for p, name in PATHS:
                if p in fl:
                    floor_rows.append([f"{s} ({items:,})", "positions + J (SSE2 kernel)",
                                       "yes, on every x86-64: `vertexPositionsAndJacobians`", fmt_time(t),
                                       f"write, {name} stores", fmt_time(fl[p]), f"{t / fl[p]:.2f}"])
            on_paths = {p: t / fl[p] for p in ("avx2", "avx512") if p in fl}
            if on_paths:
                worst = max(on_paths.values())
                measured = ", ".join(f"{dict(PATHS)[p]} floor {r:.2f}" for p, r in sorted(on_paths.items()))
                targets.append([f"positions + J within 1.25× of the write floor, {s} ({items:,})", measured,
                                verdict(worst <= 1.25, "" if worst <= 1.25 else f"over by {worst / 1.25:.2g}×")])
    e = max_error(errors, "ours_double")
    if e is not None:
        targets.append(["J error at a few ulp in double", f"{e / EPS:.2g} ε", verdict(e <= 8 * EPS, "")])
    return "\n".join(text)


NODE_ON_PATH = {"avx512": "yes, on CPUs with AVX-512F (this one)",
                "avx2": "yes, on CPUs with AVX2 + FMA but not AVX-512F",
                "sse2": "yes, on CPUs without AVX2 (the portable loop)"}


def backprop_rows(k, s):
    """The columns of the backprop table for vertex set s, and the ratios behind the targets."""
    prefix = f"backprop/{s}"
    t = cpu(k, f"{prefix}/node_columns")
    items = int(k[f"{prefix}/node_columns"]["items"])
    t2 = k.get(f"{prefix}/ours_columns_2_threads", {}).get("real")
    f, b = cpu(k, f"{prefix}/form_J_and_multiply"), cpu(k, f"{prefix}/J_buffer_then_multiply")
    cells = [f"{s} ({items:,})", fmt_time(t)]
    cells += [fmt_time(cpu(k, f"{prefix}/{key}")) for key in ("columns_on_avx2", "node_index_list", "ours_double")]
    cells += [fmt_time(t2) if t2 else "n/a", fmt_time(f), fmt_ratio(f / t) if f else "n/a", fmt_time(b),
              fmt_ratio(b / t) if b else "n/a"]
    return cells, (s, items, f / t if f else None, b / t if b else None, b * items if b else None)


def backprop_floor_targets(k, s, items, targets, floor_rows):
    prefix = f"backprop/{s}"
    fl = floors(k, prefix, "read_48B")
    on_paths = {}
    for p, name in PATHS:
        t = cpu(k, f"{prefix}/columns_on_{p}")
        if t is None or p not in fl:
            continue
        floor_rows.append([f"{s} ({items:,})", f"backprop, {name} path", NODE_ON_PATH[p], fmt_time(t),
                           f"read, {name} loads",
                           fmt_time(fl[p]), f"{t / fl[p]:.2f}"])
        if p != "sse2":
            on_paths[p] = t / fl[p]
    if on_paths and items >= 1e4:
        worst = max(on_paths.values())
        measured = ", ".join(f"{dict(PATHS)[p]} {r:.2f}" for p, r in sorted(on_paths.items()))
        targets.append([f"backprop within 1.3× of its read floor, {s} ({items:,})", measured,
                        verdict(worst <= 1.3, "" if worst <= 1.3 else f"over by {worst / 1.3:.2g}×")])


def section_backprop(k, acc, targets, floor_rows):
    errors = acc["backprop"]
    pose = cpu(k, "backprop_fixed/body_pose")
    text = ["## 3. Backprop (vector-Jacobian product)",
            "",
            "dL/dq = Σ J_iᵀ g_i. Ours never forms J: W = Σ g_i p0_iᵀ and Σ g_i, then one 3×3 product "
            "(`backpropFromSums`). **The node** (`SceneQueries::backpropConfigurations` → `vertexBackprop`) keeps each body's vertices as x, y, z "
            "arrays made once at load (24 B per vertex) and sums by coordinate (`vertex_columns.h`, "
            "detail/backprop_sums.h): one load holds 8 vertices' x (AVX-512F) or 4 (AVX2 + FMA), chosen at run time "
            "from CPUID (AVX-512F on this machine); only the client's gradients are transposed in registers. An index "
            "list goes through the same engine, gathering the listed vertices. **AVX2 path**: the same sum forced "
            "onto AVX2 + FMA (what the node runs on a CPU without AVX-512). References the node never runs: the "
            "3×N sum (`vertex_jacobian.h`, vertices stored by vertex), and the by-coordinate sum on **2 threads** "
            "(only for ≥ 2 × 65,536 vertices; wall time, since CPU time counts one thread). Baselines: J formed per "
            "vertex in registers and multiplied; and J written for all vertices (as `get_vertex_jacobians` returns "
            "it) then multiplied. Times per vertex, each call over the whole set at a new state; speed-ups are "
            "the node's. Errors relative to the sum of the terms' magnitudes (Σ|p0_i||g_i| for dL/dr, Σ|g_i| for "
            "dL/dt).",
            ""]
    rows, ratios = [], []
    for s in vertex_sets(k):
        if cpu(k, f"backprop/{s}/node_columns") is None:
            continue
        cells, r = backprop_rows(k, s)
        rows.append(cells)
        ratios.append(r)
        backprop_floor_targets(k, s, r[1], targets, floor_rows)
    text.append(md_table(["vertex set", "node: by coordinate (AVX-512F here)", "AVX2 path", "node: index list",
                          "3×N (" + NOT_NODE + ")", "2 threads, wall (" + NOT_NODE + ")",
                          "J in registers, multiply", "speed-up", "J buffer, then multiply", "speed-up"], rows))
    errs = [("node by coordinate", "ours_columns"), ("AVX2 path", "columns_on_avx2"), ("SSE2 path", "columns_on_sse2"),
            ("index list", "ours_index_list"), ("3×N", "ours_double"), ("J in registers", "form_J_and_multiply"),
            ("J buffer", "J_buffer_then_multiply")]
    text += ["", "Max rel. error: " + ", ".join(f"{label} {fmt_err(max_error(errors, key))}"
                                                 for label, key in errs if max_error(errors, key) is not None) + "."]
    fixed = cpu(k, "backprop_fixed/node_columns_no_vertices")
    if pose and fixed:
        text += ["", f"Per call, beyond its vertices, the node's kernel costs {fmt_time(fixed)} (a call with no "
                 f"vertex): the pose q → R, T (`BodyPose`, three sin/cos pairs, {fmt_time(pose)}, which the "
                 "baselines pay too), the SIMD set-up and lane reductions, and dL/dq from the sums. However fast "
                 "the per-vertex loop, a call's speed-up cannot exceed (baseline's call) ÷ (this fixed part):"]
        bounds = [[f"{s} ({items:,})", fmt_time(call), fmt_ratio(call / fixed)]
                  for s, items, _, _, call in ratios if call and call / fixed < 1000]
        if bounds:
            text += ["", md_table(["vertex set", "J buffer, then multiply, per call",
                                   "speed-up bound from the fixed part"], bounds)]
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


def section_floors(floor_rows):
    return "\n".join([
        "## 3a. Kernels against the memory they move",
        "",
        "Each kernel against a loop that only moves its bytes, once, in the same run, at each SIMD width. "
        "**Read floor** (backprop, 48 B per vertex): the gradients and the x, y, z arrays loaded once in the "
        "kernel's order (3 loads of gradients and one of each coordinate per step), added into 12 accumulators "
        "so that no add latency limits the loads; no software prefetch. **Write floor** (positions + J, 168 B per "
        "vertex): the answer's two arrays filled once with ordinary stores, or non-temporal ones where the kernel "
        "streams (from 16 MiB of J). The vertex Jacobian kernel has one path (SSE2 pairs, on every x86-64), so it "
        "is measured against the floors of each width. A ratio below 1 means the kernel beats the plain loop "
        "(e.g. through software prefetch).",
        "",
        md_table(["vertex set", "kernel", "node runs", "kernel / vertex", "floor", "floor / vertex",
                  "kernel ÷ floor"],
                 floor_rows)])


def plot_kernels(k, acc, docs):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    mass = [("mass_matrix_batch/ours_double/1", "ours_batch_single", "ours, node (K=1)"),
            ("mass_matrix/ours_float", "ours_float", "ours float (reference)"),
            ("mass_matrix/kdl", "kdl", "KDL"), ("mass_matrix/mujoco", "mujoco", "MuJoCo"),
            ("mass_matrix/fd_energy", "fd_energy", "FD of energy"),
            ("mass_matrix_batch/ours_double/64", "ours_batch_double", "ours, node (K=64)")]
    ax = axes[0]
    for name, key, label in mass:
        t = cpu(k, name)
        e = max_error(acc["mass_matrix"], key, "large_angle" if key == "ours_float" else None)
        if t is None or e is None:
            continue
        ax.loglog(max(e, 1e-17), t, "o")
        ax.annotate(label, (max(e, 1e-17), t), fontsize=8, textcoords="offset points", xytext=(5, 3))
    ax.set_title("mass matrix (one body)")
    ax.set_xlabel("max relative error vs MPFR-256")
    ax.set_ylabel("time per matrix [ns]")
    ax.grid(True, which="both", alpha=0.3)
    ax = axes[1]
    sets = vertex_sets(k)
    s = next((x for x in sets if "bunny" in x), sets[0] if sets else None)
    if s:
        jac = [("node_positions_and_J", "ours_double", "ours, node (positions + J)"),
               ("ours_float", "ours_float", "ours float (reference)"), ("kdl", "kdl", "KDL"),
               ("mujoco", "mujoco", "MuJoCo"), ("central_diff", "central_diff", "central diff."),
               ("complex_step", "complex_step", "complex step")]
        for key, err_key, label in jac:
            t = cpu(k, f"jacobian/{s}/{key}")
            e = max_error(acc["jacobian"], err_key, "large_angle" if key == "ours_float" else None)
            if t is None or e is None:
                continue
            ax.loglog(max(e, 1e-17), t, "o")
            ax.annotate(label, (max(e, 1e-17), t), fontsize=8, textcoords="offset points", xytext=(5, 3))
        fl = floors(k, f"jacobian/{s}", "write_168B")
        if fl:
            ax.axhline(min(fl.values()), linestyle="--", color="gray", linewidth=0.8,
                       label="write floor, 168 B/vertex")
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
