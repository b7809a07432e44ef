"""The "Joint-space (articulated) bodies" section of docs/benchmarks.md, from
the JSON of drb_bench_articulated (bench/bench_articulated.cpp): times are
the medians of kernel_table (CPU time per item), errors and model sizes come
from the JSON's context ("articulated.<robot>.<key>")."""
from report_format import EPS, FLOOR, NOT_NODE, PEER, fmt_ratio, fmt_time, kernel_table, md_table, verdict

ROBOTS = (("panda", "Panda"), ("ur5", "UR5"))
NODE_M = "yes: `SceneQueries::massMatrices` → `articulatedMassMatrix(body, x)` (the pose, then M)"
NODE_DM = "yes: `SceneQueries::massMatrices` with derivatives → `articulatedMassMatrixDerivatives`"
NODE_J = "yes: `articulatedVertexJacobians` on `articulatedPose` (all vertices, all columns)"
NODE_BP = "yes: `articulatedBackprop` on `articulatedPose` (all vertices)"


def fmt_err(e):
    if e is None:
        return "n/a"
    return f"{e:.2g} ({e / EPS:.2g} ε)" if e < 1e-12 else f"{e:.2g}"


def context_of(data, robot):
    prefix = f"articulated.{robot}."
    return {k[len(prefix):]: v for k, v in data.get("context", {}).items() if k.startswith(prefix)}


def number(ctx, key):
    return float(ctx[key]) if key in ctx else None


def mass_table(data):
    rows = []
    for robot, label in ROBOTS:
        c = context_of(data, robot)
        if not c:
            continue
        rows.append([label, f"{c['dofs']} coordinates, {c['segments']} segments, {float(c['mass']):.6g} kg",
                     f"{c.get('kdl.chain', 'n/a')}: {c.get('kdl.joints', '?')} joints, "
                     f"{float(c.get('kdl.mass', 'nan')):.6g} kg",
                     f"{c.get('mujoco.nv', '?')} dofs, {float(c.get('mujoco.mass', 'nan')):.6g} kg"])
    return md_table(["robot", "ours (model mode)", "KDL chain (kdl_parser)", "MuJoCo (mj_loadXML, fusestatic)"], rows)


def mass_matrix_rows(k, c, robot, targets):
    t = lambda m: k.get(f"articulated_mass_matrix/{robot}/{m}", {}).get("cpu")  # noqa: E731
    ours, kdl, mj = t("ours"), t("kdl"), t("mujoco")
    err = lambda key: number(c, "error." + key)  # noqa: E731
    ratio = lambda a, b: fmt_ratio(a / b) if a and b else "n/a"  # noqa: E731
    rows = [["ours: `articulatedPose` + `articulatedMassMatrix`", NODE_M, fmt_time(ours), ratio(kdl, ours),
             ratio(mj, ours), fmt_err(err("M.ours_vs_reference")), "—"]]
    call = t("node_call")
    if call:
        rows.append(["ours: `SceneQueries::massMatrices`, one configuration (whole call)",
                     "yes: the node's whole call (checks, answer vectors, kernel)", fmt_time(call), ratio(kdl, call),
                     ratio(mj, call), "as above", "—"])
    pose = k.get(f"articulated_pose/{robot}/ours", {}).get("cpu")
    if pose:
        rows.append(["`articulatedPose` alone (part of the rows above)", "yes: the first step of every query",
                     fmt_time(pose), "—", "—", "—", "—"])
    if t("ours_chain_mass"):
        rows.append(["ours on KDL's chain mass (off-chain segments massless)", NOT_NODE, fmt_time(t("ours_chain_mass")),
                     ratio(kdl, t("ours_chain_mass")), ratio(mj, t("ours_chain_mass")),
                     fmt_err(err("M_chain.ours_vs_reference")), "—"])
    rows.append(["KDL `ChainDynParam::JntToMass`", PEER, fmt_time(kdl), "1×", ratio(mj, kdl),
                 fmt_err(err("M_chain.kdl_vs_reference")), fmt_err(err("M_chain.ours_vs_kdl"))])
    rows.append(["MuJoCo `mj_kinematics` + `mj_comPos` + `mj_crb` + `mj_fullM`", PEER, fmt_time(mj), ratio(kdl, mj), "1×",
                 fmt_err(err("M.mujoco_vs_reference")), fmt_err(err("M.ours_vs_mujoco"))])
    rows.append(["MuJoCo `mj_fwdPosition` + `mj_fullM`", PEER, fmt_time(t("mujoco_fwdPosition")),
                 ratio(kdl, t("mujoco_fwdPosition")), ratio(mj, t("mujoco_fwdPosition")), "as above", "as above"])
    dm = t("ours_derivatives")
    rows.append(["ours: dM/dx_j for every j, `articulatedMassMatrixDerivatives`"
                 + (f" ({dm / ours:.3g}× the time of M)" if dm and ours else ""), NODE_DM, fmt_time(dm),
                 "— (no peer)", "—", fmt_err(err("dM.ours_vs_reference")), "—"])
    e = err("M.ours_vs_reference")
    if ours and kdl:
        r = kdl / ours
        few = e is not None and e <= 8 * EPS
        targets.append([f"articulated M(x) ≥ 3× faster than KDL's JntToMass at a few ulp, {robot}",
                        f"{r:.3g}×, {fmt_err(e)}",
                        verdict(r >= 3 and few, "" if r >= 3 and few else
                                (f"short by {3 / r:.2g}×" if r < 3 else "") + ("" if few else " error above 8 ε"))])
    return rows


def vertex_rows(k, c, targets):
    n = int(c.get("vertices", 0))
    if not n:
        return [], 0

    def find(kind, method):
        key = f"articulated_{kind}/panda/{method}"
        if key in k:
            return k[key]["cpu"], method
        for name, v in k.items():
            if name.startswith(key):
                return v["cpu"], name.rsplit("/", 1)[1]
        return None, method

    def row(label, node, ns, floor):
        return [label, node, fmt_time(ns * n) if ns else "n/a", f"{ns:.3g} ns" if ns else "n/a",
                fmt_ratio(ns / floor) if ns and floor else "n/a"]

    jac, _ = find("jacobian", "ours")
    wfloor, wname = find("jacobian", "floor_write")
    bp, _ = find("backprop", "ours")
    call, _ = find("backprop", "node_call")
    kernel, _ = find("backprop", "ours_kernel")
    rfloor, rname = find("backprop", "floor_read")
    dofs = int(c["dofs"])
    rows = [row(f"positions + J ({3 + 3 * dofs} doubles per vertex)", NODE_J, jac, wfloor),
            row(f"write floor, `{wname}`: the same bytes stored once", FLOOR, wfloor, wfloor),
            row("backprop dL/dx (pose included)", NODE_BP, bp, rfloor),
            row("backprop, `SceneQueries::backprop` (whole call)", "yes: the node's whole call", call, rfloor),
            row("backprop, pose made outside the loop (kernel alone)", NOT_NODE, kernel, rfloor),
            row(f"read floor, `{rname}`: gradients and vertices read once (48 B per vertex)", FLOOR, rfloor, rfloor)]
    if bp and rfloor:
        r = bp / rfloor
        targets.append([f"articulated backprop over all Panda vertices ({n:,}) ≤ 1.5× reading its inputs once",
                        f"{r:.3g}×" + (f" (whole call {call / rfloor:.3g}×" if call else " (") +
                        (f", kernel alone {kernel / rfloor:.3g}×)" if kernel else ")"),
                        verdict(r <= 1.5, "" if r <= 1.5 else f"over by {r / 1.5:.2g}×")])
    return rows, n


def section_articulated(data, targets):
    k = kernel_table(data)
    text = ["## Joint-space (articulated) bodies",
            "",
            "`drb_bench_articulated` (bench/bench_articulated.cpp): the Panda (`panda.urdf`) and the UR5 "
            "(`ur5_robot.urdf`) of test/robots/example-robot-data loaded with `JointHandling::Model`, against the "
            "same URDFs loaded by KDL (`kdl_parser::treeFromString`, then `Tree::getChain`) and MuJoCo "
            "(`mj_loadXML` on a temporary copy with `<mujoco><compiler meshdir=… strippath discardvisual fusestatic "
            "inertiafromgeom=\"false\"/></mujoco>`: the collision STLs found, visuals dropped, fixed links merged "
            "into their parent, every `<inertial>` taken as given; armature and damping 0, no gravity). Times are "
            "medians over the repetitions (CPU time, random interleaving, same run for every row), x cycling "
            "through 256 configurations uniform within the joint limits. Peer joints are matched to ours by name; "
            "a peer's M in our coordinates is Aᵀ M_peer A (A(j, c) = the mimic multiplier of joint j on coordinate "
            "c, else 1): MuJoCo ignores `<mimic>`, so its Panda has both finger joints.",
            "",
            "Mass each method covers (KDL's chain leaves out the Panda's right finger, 0.015 kg, so KDL is "
            "compared with our M of the same model with the off-chain segments massless; its time is that of its "
            "chain):",
            "",
            mass_table(data),
            "",
            "Errors: max over 66 configurations (64 random, all joints at the lower and at the upper limit) of "
            "max|ΔM| / max|M|; the reference is `articulatedMassMatrix` in 256-bit `mpfr::mpreal` on the same "
            "model, dM/dx's reference central differences of it with h = 2⁻¹⁰⁰ (9 configurations). The column "
            "\"vs ours\" is max|M_ours − M_peer| / max|M_peer|. Ratios: the peer's time over the row's (> 1: the "
            "row is faster)."]
    for robot, label in ROBOTS:
        c = context_of(data, robot)
        if not c:
            continue
        text += ["", f"### {label}: M(x), {c['dofs']} × {c['dofs']}", "",
                 md_table(["method", "node runs", "time / M", "vs KDL", "vs MuJoCo", "error vs MPFR", "vs ours"],
                          mass_matrix_rows(k, c, robot, targets))]
    rows, n = vertex_rows(k, context_of(data, "panda"), targets)
    if rows:
        text += ["", f"### Panda: vertex Jacobians and backprop over every collision-mesh vertex ({n:,})", "",
                 "One call over all of the body's vertices (every segment's, in the body frame as the model keeps "
                 "them) per iteration, the pose from x included except where said. The floors only move the "
                 "kernel's bytes once, on the widest SIMD path of this CPU (memory_floors.h), in the same run.", "",
                 md_table(["call", "node runs", "time / call", "time / vertex", "÷ floor"], rows)]
    return "\n".join(text)
