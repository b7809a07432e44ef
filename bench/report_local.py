"""docs/benchmarks.md's "In process" section (issue 30's targets) from bench/local_throughput.py's
local.json and drb_bench_local's local_kernels.json (Google Benchmark). Imported by report.py;
also runs alone:  report_local.py RESULTS_DIR  (prints the section and its target rows)."""
import os
import sys

from report_format import fmt_ratio, kernel_table, load, md_table, verdict

MEMORY_SLACK = 1 << 20  # [B]: one configuration's workspace per thread and allocator pages


def ms(seconds):
    if seconds is None:
        return "n/a"
    return f"{seconds * 1e6:.1f} µs" if seconds < 1e-3 else f"{seconds * 1e3:.2f} ms"


def kernel_seconds(kernels, name):
    """Wall time [s] per call of drb_bench_local's row ``name`` (median over repetitions)."""
    row = kernels.get(name)
    return row["real"] * 1e-9 if row else None


def ratio(a, b):
    return a / b if a is not None and b else None


def call_rows(local, kernels):
    """(label, core [s], module [s], LocalScene [s], node [s]) per call."""
    rows = []
    labels = {"ur5/mass_matrix_K1": "M, UR5 (6 coordinates), K = 1",
              "panda/mass_matrix_K1": "M, Panda (8 coordinates), K = 1",
              "ur5/backprop_K1000_N400": "backprop, UR5, K = 1000, 400 vertices"}
    node = local.get("node", {})
    for key, label in labels.items():
        x = local["kernel"][key]
        n = node.get(key, {}).get("node")
        core = x["core"]["median"] if "core" in x else kernel_seconds(kernels, "local/" + key)  # taking turns
        rows.append((key, label, core, x["module"]["median"],
                     x["local"]["median"], n["median"] if n else None))
    t = local["trajectory"]
    n = node.get("trajectory_T1000", {}).get("node")
    rows.append(("trajectory_T1000", "trajectory loss + gradient (torch), T = 1000", t["kernels"]["median"], None,
                 t["local"]["median"], n["median"] if n else None))
    return rows


def speed_targets(rows, local, targets):
    by = {r[0]: r for r in rows}
    for key, what in (("ur5/mass_matrix_K1", "(a) M, UR5, K = 1"), ("panda/mass_matrix_K1", "(a) M, Panda, K = 1"),
                      ("ur5/backprop_K1000_N400", "(b) backprop, UR5, K = 1000, 400 vertices")):
        _, _, core, module, own, _ = by[key]
        r = ratio(own, core)
        why = "" if r is not None and r <= 1.3 else (
            f"the call's fixed cost in Python: LocalScene {ms(own)}, of which the compiled module's call "
            f"{ms(module)} (pybind11 and numpy over the core's {ms(core)}) and the Python wrapper "
            f"{ms(own - module)} (request checks, answer shaping)" + (
                "; at this scale the module runs the same core function on the same arrays, so a gap between "
                "them is the machine's load, not Python's" if core and core > 1e-4 and module > 1.1 * core else ""))
        if r is not None and r < 0.95:  # LocalScene runs this very core call: below it is not a speed-up
            why = (f"below 1× because the C++ row ran slower in its own process ({ms(core)}) than the same core "
                   f"call inside Python (the module's {ms(module)}); against the module call LocalScene is "
                   f"{fmt_ratio(ratio(own, module))}")
        targets.append([f"Issue 30: in process (LocalScene) ≤ 1.3× its C++ core call, {what}", fmt_ratio(r),
                        verdict(r is not None and r <= 1.3, why)])
    _, _, kernels_s, _, own, _ = by["trajectory_T1000"]
    r = ratio(own, kernels_s)
    calls = local["trajectory"].get("in_calls")
    why = "" if r and r <= 1.5 else (
        f"the core's two calls take {ms(kernels_s)}; " +
        ("" if calls is None else f"LocalScene.call {ms(calls)} (the client's request checks and answer shaping "
         f"{ms(calls - kernels_s)}), ") + f"torch (trajectory, autograd) and the client's Python the rest of "
        f"{ms(own)}: fixed costs that do not shrink with the core's {ms(kernels_s / 1000)} per frame")
    targets.append(["Issue 30: torch trajectory gradient in process, T = 1000, ≤ 1.5× the core's time for the "
                    "same calls", fmt_ratio(r), verdict(r is not None and r <= 1.5, why)])
    for key, what, goal in (("ur5/backprop_K1000_N400", "backprop, UR5, K = 1000 (9.6 MB up)", 5.0),
                            ("trajectory_T1000", "trajectory gradient, T = 1000", 4.0)):
        _, _, core, _, own, node = by[key]
        r = ratio(node, own)
        if node is None:
            targets.append([f"Issue 30: in process ≥ {goal:g}× faster than the node (tcpros buffers), {what}",
                            "n/a", "not measured (no node run)"])
            continue
        why = "" if r >= goal else (f"the node adds {ms(node - own)} (transport, its handling) to the {ms(own)} "
                                    f"that both pay (the core's {ms(core)} of it); {goal:g}× needs it to add "
                                    f"{ms((goal - 1) * own)}")
        targets.append([f"Issue 30: in process ≥ {goal:g}× faster than the node (tcpros buffers), {what}",
                        fmt_ratio(r), verdict(r >= goal, why)])


def dask_target(dask, targets):
    one, two = dask["workers_1"], dask["workers_2"]
    r = one["median"] / two["median"]
    same = one["same_bits"] and two["same_bits"]
    why = []
    if r < 1.6:
        c1, c2 = one.get("compute_only"), two.get("compute_only")
        split = "" if c1 is None else (
            f"computing alone (answers left on the workers) takes {c1:.2f} s with 1 worker and {c2:.2f} s with 2 "
            f"({c1 / c2:.2f}×); gathering and joining the answer adds {one['median'] - c1:.1f} s and "
            f"{two['median'] - c2:.1f} s: ")
        why.append(split + f"the {dask['answer_bytes'] / 1e6:.0f} MB answer reaches the one client process over "
                   f"TCP and is unpickled and joined there, whatever the workers (in process, the whole batch takes "
                   f"{dask['single_process']:.2f} s)")
    if not same:
        why.append("answers NOT bit for bit equal to one LocalScene call")
    targets.append([f"Issue 30: Dask LocalCluster, 2 workers ≥ 1.6× 1 worker, forward dynamics with derivatives, "
                    f"floating humanoid, K = {dask['K']:,}; bit for bit", f"{fmt_ratio(r)}, bits "
                    + ("equal" if same else "DIFFER"), verdict(r >= 1.6 and same, "; ".join(why))])


def memory_target(memory, targets):
    for m in memory:
        increase, answer = m["after"] - m["before"], m["answer_bytes"]
        ok = increase <= answer + MEMORY_SLACK
        targets.append([f"Issue 30: K = {m['K']:,} in process ({m['kind']}): peak RSS increase ≤ the answer + "
                        "1 MiB (workspace per thread)", f"+{increase / 1e6:.1f} MB for {answer / 1e6:.1f} MB",
                        verdict(ok, "" if ok else f"{(increase - answer) / 1e6:.1f} MB over the answer: "
                                "temporaries of the call")])


def section_local(local, kernels_json, targets):
    kernels = kernel_table(kernels_json) if kernels_json else {}
    rows = call_rows(local, kernels)
    table = [[label, ms(core), ms(module), ms(own), ms(node), fmt_ratio(ratio(own, core)), fmt_ratio(ratio(node, own))]
             for _, label, core, module, own, node in rows]
    dask = local["dask"]
    dask_rows = [[f"LocalScene in this process ({dask['reference_calls']} calls, joined)",
                  f"{dask['single_process']:.2f} s", "—", "—", "(reference)"]]
    for n in (1, 2):
        w = dask[f"workers_{n}"]
        c = w.get("compute_only")
        dask_rows.append([f"LocalCluster, {n} worker process{'es' if n > 1 else ''} × 1 thread",
                          f"{w['median']:.2f} s", fmt_ratio(dask['workers_1']['median'] / w['median']),
                          "n/a" if c is None else f"{c:.2f} s", "yes" if w["same_bits"] else "NO"])
    memory_rows = [[m["kind"], f"{m['K']:,}", "×".join(str(s) for s in m["shape"]),
                    f"{m['answer_bytes'] / 1e6:.1f} MB", f"{m['before'] / 1e6:.1f} MB", f"{m['after'] / 1e6:.1f} MB",
                    f"{(m['after'] - m['before']) / 1e6:.1f} MB"] for m in local["memory"]]
    node_same = [f"{k}: {'yes' if v.get('same_bits') else 'NO'}" for k, v in local.get("node", {}).items()]
    own_targets = []
    speed_targets(rows, local, own_targets)
    dask_target(dask, own_targets)
    memory_target(local["memory"], own_targets)
    targets.extend(own_targets)
    text = ["## In process: `diff_rigid_body.LocalScene`", "",
            "bench/local_throughput.py (" + local["machine"] + (", quick run" if local.get("quick") else "") + ") and "
            "drb_bench_local (bench/bench_local.cpp): the same inputs (exact binary fractions, formulas in "
            "bench_local.cpp) through the C++ core call LocalScene makes (`SceneQueries::massMatrices` / "
            "`backpropConfigurations`, a fresh answer per call, the 9.6 MB of gradients on transparent huge pages as "
            "numpy allocates them; Google Benchmark wall time: one drb_bench_local run per window, taking turns with "
            "the Python windows, or else the median of its repetitions), the compiled "
            "module's call alone (`diff_rigid_body._local`), `LocalScene`'s method, and the node through "
            "`RigidBodyClient`'s tcpros buffer transport (`rigid_body_server` under its own roscore, same "
            "machine)." + (" 1-minute load average %.2f at the start, %.2f at the end." % tuple(local["load"])
                           if "load" in local else "") +
            f" Times: median over {local['windows']} windows of ≥ "
            f"{local['window_s']:g} s of the mean per call, the columns of a row taking turns window by window. The trajectory row is bench/client_trajectory.py's batched "
            "loss and gradient; its core column is the same module calls replayed (" +
            ", ".join(local["trajectory"]["calls"]) + ").", "",
            md_table(["call", "C++ core", "module call", "LocalScene", "node (tcpros)", "LocalScene ÷ core",
                      "node ÷ LocalScene"], table), "",
            "Node answers bit for bit equal to LocalScene's: " + (", ".join(node_same) or "n/a (no node run)") + ".",
            "", f"### Dask: forward dynamics with derivatives, floating humanoid ({dask['coordinates']} coordinates), "
            f"K = {dask['K']:,}", "",
            f"`diff_rigid_body.dask_batches.map_configurations` on a `distributed.LocalCluster` (scenes loaded by a "
            f"first call; median of the calls after it); answer {dask['answer_bytes'] / 1e6:.0f} MB. One LocalScene "
            "call of all K is refused (over the core's 25.2 M answer values), so the reference is LocalScene calls of "
            "5,000 configurations joined (each configuration is computed on its own). \"computing\": the same "
            "shards with their answers left on the workers (no gather).", "",
            md_table(["how", "wall time", "speed-up over 1 worker", "computing", "bit for bit = LocalScene"],
                     dask_rows),
            "", "### Memory of a K = 100,000 batch", "",
            "A fresh process loads the UR5, calls once at K = 1 (its workspace), builds q, resets its peak RSS "
            "(`/proc/self/clear_refs` 5: VmHWM := VmRSS), then reads RSS before and the peak (VmHWM) after one "
            "K-configuration call (M with cos θ; positions of 32 vertices, "
            "`vertex_jacobians_compact(positions_only=True)`). `ru_maxrss` cannot show it: the peak of loading "
            "the meshes (" + ", ".join(f"{m['maxrss_before'] / 1e6:.0f} MB" for m in local["memory"]) +
            ") is above the batch's (`ru_maxrss` after: " +
            ", ".join(f"{m['maxrss_after'] / 1e6:.0f} MB" for m in local["memory"]) + ").", "",
            md_table(["answer", "K", "shape", "answer bytes", "RSS before", "peak during the call", "increase"],
                     memory_rows),
            "", "### Targets (issue 30)", "", md_table(["target", "measured", "verdict"], own_targets)]
    return "\n".join(text)


def section_from(results, targets):
    """The section when local.json is in ``results`` (else None)."""
    path = os.path.join(results, "local.json")
    if not os.path.exists(path):
        return None
    local = load(path)
    missing = [part for part in ("kernel", "trajectory", "memory", "dask") if part not in local]
    if missing:
        return ("## In process: `diff_rigid_body.LocalScene`\n\nIncomplete run of bench/local_throughput.py "
                "(--parts): no " + ", ".join(missing) + ".")
    kernels_path = os.path.join(results, "local_kernels.json")
    return section_local(local, load(kernels_path) if os.path.exists(kernels_path) else None, targets)


if __name__ == "__main__":
    print(section_from(sys.argv[1], []))
