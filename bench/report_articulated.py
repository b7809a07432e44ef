"""The "Bodies with joints" section of docs/benchmarks.md and its targets
(issues 18 and 20), from the JSON of drb_bench_articulated
(bench/bench_articulated.cpp): times are the medians of kernel_table (CPU
time per item), errors and model sizes come from the JSON's context
("articulated.<robot>.<key>")."""
from report_format import EPS, FLOOR, NOT_NODE, PEER, fmt_ratio, fmt_time, kernel_table, md_table
from report_targets import articulated_targets

ROBOTS = ("panda", "ur5", "humanoid", "humanoid_floating")
NODE_M = "yes: `SceneQueries::massMatrices` → `crba(model, ws, x)` per body"
NODE_DM = "yes: `SceneQueries::massMatrices` with derivatives → `massMatrixDerivatives`"
NODE_ID = "yes: `SceneQueries::inverseDynamics` → `inverseDynamics`"
NODE_DID = "yes: `SceneQueries::inverseDynamics` with derivatives → `inverseDynamicsDerivatives`"
NODE_FD = "yes: `SceneQueries::forwardDynamics` → `forwardDynamics`"
NODE_DFD = "yes: `SceneQueries::forwardDynamics` with derivatives → `forwardDynamicsDerivatives`"
NODE_J = "yes: `SceneQueries::vertexJacobians` → `vertexJacobians<double>` (all vertices, all columns)"
NODE_BP = "yes: `SceneQueries::backpropConfigurations` → `vertexBackprop` (all vertices)"


def fmt_err(e):
    if e is None:
        return "n/a"
    return f"{e:.2g} ({e / EPS:.2g} ε)" if e < 1e-12 else f"{e:.2g}"


def context_of(data, robot):
    prefix = f"articulated.{robot}."
    return {k[len(prefix):]: v for k, v in data.get("context", {}).items() if k.startswith(prefix)}


class Rows:
    """Times and errors of one robot."""

    def __init__(self, k, data, robot):
        self.k, self.robot, self.c = k, robot, context_of(data, robot)

    def t(self, quantity, method):
        return self.k.get(f"{quantity}/{self.robot}/{method}", {}).get("cpu")

    def find(self, quantity, prefix):
        """(time, method) of the first row whose method starts with `prefix`."""
        key = f"{quantity}/{self.robot}/{prefix}"
        for name, v in self.k.items():
            if name.startswith(key):
                return v["cpu"], name.rsplit("/", 1)[1]
        return None, prefix

    def err(self, key):
        return float(self.c["error." + key]) if "error." + key in self.c else None


def ratio(a, b):
    return fmt_ratio(a / b) if a and b else "n/a"


def model_table(data):
    rows = []
    for robot in ROBOTS:
        c = context_of(data, robot)
        if not c:
            continue
        rows.append([c["label"], f"{c['coordinates']} coordinates in {c['bodies']} bod{'y' if c['bodies'] == '1' else 'ies'}"
                     f", {c['segments']} segments, {float(c['mass']):.6g} kg, {c['vertices']} vertices",
                     f"{c.get('kdl.chain', 'n/a')}: {c.get('kdl.joints', '?')} joints, "
                     f"{float(c.get('kdl.mass', 'nan')):.6g} kg",
                     f"{c.get('mujoco.nv', '?')} dofs, {float(c.get('mujoco.mass', 'nan')):.6g} kg",
                     f"nq {c.get('pinocchio.nq', '?')}, nv {c.get('pinocchio.nv', '?')}"])
    return md_table(["robot", "ours (model mode)", "KDL chain (kdl_parser)", "MuJoCo (mj_loadXML, fusestatic)",
                     "Pinocchio (timing model)"], rows)


def mass_matrix_table(r):
    ours, pin, kdl, mj = (r.t("mass_matrix", m) for m in ("ours", "pinocchio", "kdl", "mujoco"))

    def row(label, node, time, error="—"):
        return [label, node, fmt_time(time), ratio(pin, time), ratio(kdl, time), ratio(mj, time), error]

    rows = [row("ours: `crba(model, ws, x)` (kinematics included)", NODE_M, ours, fmt_err(r.err("M.ours"))),
            row("ours: `SceneQueries::massMatrices`, one configuration, answer reused (whole call)",
                "yes: the node's whole call (checks, answer, kernel)", r.t("mass_matrix", "node_call"), "as above")]
    kin = r.t("kinematics", "ours")
    rows.append(["ours: `forwardKinematics` alone (part of the rows above)", "yes: the first step of every query",
                 fmt_time(kin), ratio(r.t("kinematics", "pinocchio"), kin) + " (vs its forwardKinematics)", "—", "—",
                 "—"])
    if r.t("mass_matrix", "ours_chain_mass"):
        rows.append(row("ours on KDL's chain mass (off-chain segments massless)", NOT_NODE,
                        r.t("mass_matrix", "ours_chain_mass"), fmt_err(r.err("M.ours_chain_mass"))))
    rows.append(row("Pinocchio `crba` (+ lower triangle)", PEER, pin, fmt_err(r.err("M.pinocchio"))))
    rows.append(row("KDL `ChainDynParam::JntToMass` (its chain)", PEER, kdl, fmt_err(r.err("M.kdl"))))
    rows.append(row("MuJoCo `mj_kinematics` + `mj_comPos` + `mj_crb` + `mj_fullM`", PEER, mj, fmt_err(r.err("M.mujoco"))))
    rows.append(["Pinocchio `forwardKinematics`", PEER, fmt_time(r.t("kinematics", "pinocchio")), "—", "—", "—", "—"])
    dm = r.t("mass_matrix_derivatives", "ours")
    rows.append(["ours: dM/dx_j for every j, `massMatrixDerivatives`" + (f" ({dm / ours:.3g}× one M)" if dm and ours
                                                                         else ""),
                 NODE_DM, fmt_time(dm), "— (no peer)", "—", "—", fmt_err(r.err("dM.ours"))])
    return md_table(["method", "node runs", "time / M", "vs Pinocchio", "vs KDL", "vs MuJoCo", "error vs MPFR"], rows)


def dynamics_table(r):
    t_id, t_m, t_fd = r.t("inverse_dynamics", "ours"), r.t("mass_matrix", "ours"), r.t("forward_dynamics", "ours")
    rows = []

    def row(label, node, quantity, method, base=None, base_name="", error="—"):
        time = r.t(quantity, method)
        versus = [ratio(r.t(quantity, p), time) if method == "ours" and r.t(quantity, p) else "—"
                  for p in ("pinocchio", "kdl", "mujoco")]
        rows.append([label, node, fmt_time(time)] + versus +
                    [f"{time / base:.3g}× {base_name}" if time and base else "—", error])

    errs = lambda *keys: ", ".join(f"{k.split('.')[0]} {fmt_err(r.err(k))}" for k in keys if r.err(k) is not None) or "n/a"  # noqa: E731,E501
    row("ours: τ, `inverseDynamics`", NODE_ID, "inverse_dynamics", "ours", error=errs("tau.ours"))
    row("Pinocchio `rnea`", PEER, "inverse_dynamics", "pinocchio", error=errs("tau.pinocchio"))
    row("KDL `ChainIdSolver_RNE` (its chain)", PEER, "inverse_dynamics", "kdl", error=errs("tau.kdl"))
    row("MuJoCo `mj_kinematics` + `mj_comPos` + `mj_comVel` + `mj_rne`", PEER, "inverse_dynamics", "mujoco",
        error=errs("tau.mujoco"))
    row("ours: ∂τ/∂x and ∂τ/∂ẋ, `inverseDynamicsDerivatives`", NODE_DID, "inverse_dynamics_derivatives", "ours",
        t_id, "one ID", errs("dtau_dx.ours", "dtau_dxd.ours"))
    row("Pinocchio `computeRNEADerivatives`", PEER, "inverse_dynamics_derivatives", "pinocchio", t_id, "our ID",
        errs("dtau_dx.pinocchio", "dtau_dxd.pinocchio"))
    row("ours: ẍ, `forwardDynamics`", NODE_FD, "forward_dynamics", "ours", t_m, "one M", errs("fd.ours"))
    row("Pinocchio `aba`", PEER, "forward_dynamics", "pinocchio", t_m, "our M", errs("fd.pinocchio"))
    row("ours: ∂ẍ/∂x, ∂ẍ/∂ẋ, M⁻¹, `forwardDynamicsDerivatives`", NODE_DFD, "forward_dynamics_derivatives", "ours",
        t_fd, "one FD", errs("dfd_dx.ours", "dfd_dxd.ours", "minv.ours"))
    row("Pinocchio `computeABADerivatives`", PEER, "forward_dynamics_derivatives", "pinocchio", t_fd, "our FD",
        errs("dfd_dx.pinocchio", "dfd_dxd.pinocchio", "minv.pinocchio"))
    return md_table(["method", "node runs", "time", "vs Pinocchio", "vs KDL", "vs MuJoCo", "÷ base", "error vs MPFR"],
                    rows)


def vertex_table(r):
    n = int(r.c.get("vertices", 0))
    d = int(r.c["coordinates"])
    jac, _ = r.find("jacobian", "ours")
    wfloor, wname = r.find("jacobian", "floor_write")
    pin, _ = r.find("jacobian", "pinocchio")
    bp, _ = r.find("backprop", "ours")
    call, _ = r.find("backprop", "node_call")
    rfloor, rname = r.find("backprop", "floor_read")

    def row(label, node, ns, floor, per_vertex=True):
        return [label, node, fmt_time(ns * n) if ns else "n/a", f"{ns:.3g} ns" if ns and per_vertex else "—",
                fmt_ratio(ns / floor) if ns and floor and per_vertex else "—"]

    return md_table(["call", "node runs", "time / call", "time / vertex", "÷ floor"], [
        row(f"positions + J ({3 + 3 * d} doubles per vertex), pose included", NODE_J, jac, wfloor),
        row(f"write floor, `{wname}`: the same bytes stored once", FLOOR, wfloor, wfloor),
        row(f"Pinocchio `computeJointJacobians` (6 × {r.c.get('pinocchio.nv', '?')}, per call: no vertex)", PEER,
            pin, None, False),
        row("backprop dL/dx, `vertexBackprop`, pose included", NODE_BP, bp, rfloor),
        row("backprop, `SceneQueries::backpropConfigurations`, one configuration (whole call)",
            "yes: the node's whole call", call, rfloor),
        row(f"read floor, `{rname}`: gradients and vertex columns read once (48 B per vertex)", FLOOR, rfloor, rfloor)])


NODE_FRAME = "yes: `SceneQueries::frameJacobians` → `forwardKinematicsOf` (the frame's path) + `frameJacobian`"
NODE_COM = "yes: `SceneQueries::centerOfMass` with Jacobians → `centerOfMass`"


def frames_table(r):
    def row(label, node, quantity, method):
        time, ours = r.t(quantity, method), r.t(quantity, "ours")
        return [label, node, fmt_time(time), ratio(time, ours) if method != "ours" else "1"]

    rows = [row("ours: pose + 6 × d Jacobian, `frameJacobian`", NODE_FRAME, "frame_jacobian", "ours"),
            row("ours: `SceneQueries::frameJacobians`, that frame, one configuration (whole call)",
                "yes: the node's whole call", "frame_jacobian", "node_call"),
            row("Pinocchio `computeFrameJacobian` (LOCAL_WORLD_ALIGNED)", PEER, "frame_jacobian", "pinocchio"),
            row("KDL `ChainJntToJacSolver::JntToJac` (its chain)", PEER, "frame_jacobian", "kdl"),
            row("MuJoCo `mj_kinematics` + `mj_comPos` + `mj_jacBody`", PEER, "frame_jacobian", "mujoco")]
    if r.t("com_jacobian", "ours"):
        rows += [row("ours: centre of mass + 3 × d Jacobian, `centerOfMass`", NODE_COM, "com_jacobian", "ours"),
                 row("Pinocchio `jacobianCenterOfMass` (whole model)", PEER, "com_jacobian", "pinocchio"),
                 row("MuJoCo `mj_kinematics` + `mj_comPos` + `mj_jacSubtreeCom`", PEER, "com_jacobian", "mujoco")]
    return md_table(["method", "node runs", "time", "÷ ours"], rows)


def section_articulated(data, targets):
    k = kernel_table(data)
    rows = {robot: Rows(k, data, robot) for robot in ROBOTS if context_of(data, robot)}
    text = ["## Bodies with joints: kinematics, M, dM/dx, vertices, dynamics",
            "",
            "`drb_bench_articulated` (bench/bench_articulated.cpp, bench_bodies.cpp, bench_dynamics.cpp): the Panda "
            "(`panda.urdf`), the UR5 (`ur5_robot.urdf`) and simple_humanoid of test/robots/drb_example_robot_data loaded "
            "with `JointHandling::Model`; the humanoid on its fixed base (BODY is welded to base_link, so its legs "
            "and its waist with torso and arms are three fixed-base bodies, 29 coordinates, timed together) and with "
            "its `waist` joint made `floating` (one body, a free root with 29 joints: 35 coordinates). Peers on the "
            "same URDFs in the same process: Pinocchio 3.7.0 (vendored, bench/pinocchio_peer.h; the floating "
            "humanoid timed as Pinocchio's own `JointModelFreeFlyer` model, its errors taken on the EulerZYX chain "
            "that is our free root), KDL (`kdl_parser`, `Tree::getChain`: a chain on a fixed base, so the humanoid's "
            "longest chain base_link..l_wrist, 10 of 29 joints, for both humanoids) and MuJoCo (`mj_loadXML` on a "
            "copy with `<compiler fusestatic discardvisual inertiafromgeom=\"false\"/>`; the whole tree, the floating "
            "humanoid on MuJoCo's free joint; the humanoid's ASCII STL box, which MuJoCo cannot read, left out of "
            "its copy: no geometry enters M or τ). Gravity "
            "(0, 0, −9.81) m/s² for all. Times: CPU time per item, medians over the repetitions (random "
            "interleaving, same run for every row), cycling through 256 states uniform within the joint limits "
            "(a free root: φ, ψ in [−π, π], θ in [−1.2, 1.2], COM in [−1, 1]³ m; ẋ in [−2, 2], ẍ and τ in [−3, 3]). "
            "Peer joints are matched to ours by name: with A(j, c) the mimic multiplier of peer joint j on our "
            "coordinate c (else 1), M = Aᵀ M_peer A and τ = Aᵀ τ_peer at q = A x + offset, v = A ẋ, a = A ẍ "
            "(the Panda's right finger mimics its left; Pinocchio and MuJoCo take it as its own dof).",
            "",
            model_table(data),
            "",
            "Errors: max over 66 states (64 random, all joints at their lower and at their upper limits) of "
            "max|Δ| / max|ref|, in units of ε = 2⁻⁵²; the reference is our own kernel evaluated in 256-bit "
            "`mpfr::mpreal` on the same model (crba, inverseDynamics, forwardDynamics and its M⁻¹), derivatives' "
            "references central differences of it with h = 2⁻¹⁰⁰ (dM/dx and ∂τ on 9 states, ∂ẍ on 5). KDL is "
            "compared with the reference of the mass its chain covers; MuJoCo only without a free joint; "
            "Pinocchio's ẍ and ABA derivatives only without mimic joints (its independent finger is another "
            "system). Ratios \"vs peer\": the peer's time over the row's (> 1: the row is faster); \"÷ base\": the "
            "row's time over one of ours."]
    for robot, r in rows.items():
        text += ["", f"### {r.c['label']}: M(x), {r.c['coordinates']} × {r.c['coordinates']}", "",
                 mass_matrix_table(r),
                 "", f"### {r.c['label']}: dynamics", "",
                 f"M's condition number λmax/λmin reaches {float(r.c.get('conditioning.M', 'nan')):.3g} over the "
                 "error states: ẍ and M⁻¹ may carry that many ε of relative error, whatever the method.", "",
                 dynamics_table(r)]
        if r.t("frame_jacobian", "ours"):
            text += ["", f"### {r.c['label']}: a link frame's Jacobian (`{r.c.get('kdl.chain', '?').split('..')[-1]}`, "
                     "KDL's chain tip) and the centre of mass", "",
                     "One configuration per iteration, the poses of the supporting links included; LOCAL_WORLD_ALIGNED "
                     "(the tip's origin, fixed-frame axes) for every method. Agreement is tested, not timed "
                     "(test_dynamics_pinocchio.cpp, test_frames_kdl_mujoco.cpp: within 1e-11 relative).", "",
                     frames_table(r)]
        if r.find("jacobian", "ours")[0]:
            text += ["", f"### {r.c['label']}: vertex Jacobians and backprop over every collision-mesh vertex "
                     f"({int(r.c['vertices']):,})", "",
                     "One call over all of the body's vertices per iteration, the pose from x included. The floors "
                     "only move the kernel's bytes once, on the widest SIMD path of this CPU (memory_floors.h), "
                     "in the same run.", "", vertex_table(r)]
    targets.extend(articulated_targets(rows))
    return "\n".join(text)
