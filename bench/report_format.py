"""Shared helpers of bench/report.py: loading the benchmark JSON, number
formatting and markdown tables."""
import json
import math
import re

EPS = 2.0 ** -52  # double epsilon: errors are also given in units of it

# ---------------------------------------------------------------------------
# Loading.


def load(path):
    with open(path) as f:
        return json.load(f)


def kernel_table(kernels):
    """run name -> {'cpu': ns per item, 'real': ns per item, 'items': n} from the medians."""
    table = {}
    # One repetition (DRB_BENCH_QUICK=1) gives no aggregates: take the runs.
    medians = any(b.get("aggregate_name") == "median" for b in kernels["benchmarks"])
    for b in kernels["benchmarks"]:
        if medians and (b.get("run_type") != "aggregate" or b.get("aggregate_name") != "median"):
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




NOT_NODE = "not on the node's path: reference only"
PEER = "not on the node's path: peer"
FLOOR = "not on the node's path: memory floor"
