"""The "Near gimbal lock" section of docs/benchmarks.md, from the JSON of
drb_bench_gimbal: errors of forward dynamics and its derivatives against MPFR
as a function of k, theta = +-(pi/2 - 10^-k), beside a solve with M."""
from report_format import fmt_err, md_table, verdict

ACCELERATION_TARGET = 1e-13
DERIVATIVE_TARGET = 1e-9
LABELS = {"free_brick": "free brick (a full inertia tensor, 6 coordinates)",
          "floating_humanoid": "floating humanoid (35 coordinates)"}


def section_gimbal(data, targets):
    text = ["## Near gimbal lock: forward dynamics against MPFR",
            "",
            "Pitch θ = ±(π/2 − 10⁻ᵏ) as doubles, the other angles, rates and forces random; the worse of the "
            "two signs, normwise relative (max|ours − ref| / max|ref|) against a 256-bit reference that "
            "solves M ẍ = τ − c − g (`test/support/gimbal_reference.h`, the unit test's; derivatives by "
            "central differences in MPFR, every column). *ours*: `forwardDynamicsDerivatives`, the node's "
            "kernel (motion coordinates inside, the chart at the edge: docs/derivation.md, \"Conditioning "
            "near gimbal lock\"). *solve with M*: ẍ from Eigen's LDLᵀ of the same M, c and g in double, "
            "what the route before this version lost (cond M ~ 1/cos²θ; the node refused from k = 7)."]
    worst = {"xdd": 0.0, "derivatives": 0.0}
    for body in ("free_brick", "floating_humanoid"):
        if body not in data:
            continue
        rows = []
        for r in data[body]["rows"]:
            rows.append([str(r["k"]), f"{10.0 ** -r['k']:.0e}", fmt_err(r["xdd"]), fmt_err(r["dxdd_dx"]),
                         fmt_err(r["dxdd_dxd"]), fmt_err(r["minv"]), fmt_err(r["solve_m"])])
            worst["xdd"] = max(worst["xdd"], r["xdd"])
            worst["derivatives"] = max(worst["derivatives"], r["dxdd_dx"], r["dxdd_dxd"], r["minv"])
        text += ["", f"### {LABELS[body]}", "",
                 md_table(["k", "≈ cos θ", "ẍ", "∂ẍ/∂x", "∂ẍ/∂ẋ", "M⁻¹", "ẍ, solve with M"], rows)]
    targets.append(["Issue 28: near gimbal lock (k = 1…12, free brick and floating humanoid), ẍ within 1e-13 "
                    "normwise relative of MPFR", fmt_err(worst["xdd"]),
                    verdict(worst["xdd"] <= ACCELERATION_TARGET, "")])
    targets.append(["Issue 28: near gimbal lock, ∂ẍ/∂x, ∂ẍ/∂ẋ (and M⁻¹) within 1e-9", fmt_err(worst["derivatives"]),
                    verdict(worst["derivatives"] <= DERIVATIVE_TARGET, "")])
    return "\n".join(text)
