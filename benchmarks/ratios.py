#!/usr/bin/env python3
"""Ratios KDL / extwrench, the medians table and the latency table from a bench.json.

Usage: python3 benchmarks/ratios.py [build/bench.json] [--markdown] [--real]

Reads the JSON that `make bench` writes (Google Benchmark, --benchmark_repetitions=5 with
aggregates); uses each benchmark's median over the repetitions. Times are CPU time by default
(robust when other processes share the cores); --real uses wall-clock time. --markdown prints
the tables of BENCHMARKS.md instead of the console summary. Standard library only.
"""
import json
import sys

# (label, KDL benchmark, our benchmark, acceptance target for KDL/ours or None)
PAIRS = [
    ("RNEA + base wrench vs KDL RNE", "BM_Rnea_Kdl", "BM_RneaBaseWrench_Ours", 3.0),
    ("RNEA (torques only) vs KDL RNE", "BM_Rnea_Kdl", "BM_Rnea_Ours", None),
    ("mass matrix vs ChainDynParam::JntToMass", "BM_MassMatrix_Kdl", "BM_MassMatrix_Ours", None),
    ("flange Jacobian vs ChainJntToJacSolver", "BM_Jacobian_Kdl", "BM_Jacobian_Ours", None),
    ("flange Jacobian after forward_poses vs ChainJntToJacSolver",
     "BM_Jacobian_Kdl", "BM_JacobianPoses_Ours", 5.0),
    ("gravity g(q) vs ChainDynParam::JntToGravity", "BM_Gravity_Kdl", "BM_Gravity_Ours", 6.0),
    ("bias C q̇ + g vs ChainDynParam::JntToCoriolis (C q̇ only)",
     "BM_Coriolis_Kdl", "BM_Bias_Ours", None),
    ("residual model terms (Bq̇, Cᵀq̇, g) vs JntToMass+Coriolis+Gravity",
     "BM_MomentumTerms_Kdl", "BM_MomentumTerms_Ours", None),
    ("residual + EE wrench (case E, l = n) vs JntToExtWrench",
     "BM_ExtWrench_Kdl", "BM_ResidualEeWrench_Ours", 8.0),
    ("residual alone vs JntToExtWrench", "BM_ExtWrench_Kdl", "BM_Residual_Ours", None),
    ("full update, F/T, unknown point, capsules vs JntToExtWrench",
     "BM_ExtWrench_Kdl", "BM_FullUpdate_Ours/ft/pure_force/capsules", 5.0),
]
# (label, our earlier path, our current one, target for earlier/current or None): speed-ups of
# our own code, measured in the same run.
SELF_PAIRS = [
    ("gravity: the whole bias pass (before issue 15) / the gravity pass",
     "BM_GravityBiasPass_Ours", "BM_Gravity_Ours", 2.0),
]
FULL_PREFIX = "BM_FullUpdate_Ours/"
LATENCY_PREFIX = "BM_Latency_"
TO_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}


def load(path, use_real):
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    runs = {}  # run_name -> entry (median aggregate preferred, else the single run)
    for b in doc.get("benchmarks", []):
        name = b.get("run_name", b["name"]).replace("/iterations:1/repeats:1", "")
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") != "median":
                continue
        elif name in runs:
            continue  # several iterations without aggregates: keep the first
        entry = dict(b)
        key = "real_time" if use_real else "cpu_time"
        entry["ns"] = b[key] * TO_NS[b.get("time_unit", "ns")]
        runs[name] = entry
    return doc.get("context", {}), runs


def fmt_ns(ns):
    return f"{ns / 1000:.2f} µs" if ns >= 1000 else f"{ns:.0f} ns"


def fmt_allocs(entry):
    a = entry.get("allocs")
    return "–" if a is None else (f"{a:.0f}" if abs(a - round(a)) < 1e-9 else f"{a:.2f}")


def ratio_rows(runs):
    rows = []
    for label, kdl, ours, target in PAIRS:
        if kdl in runs and ours in runs:
            r = runs[kdl]["ns"] / runs[ours]["ns"]
            verdict = "" if target is None else ("met" if r >= target else "NOT MET")
            rows.append((label, runs[kdl], runs[ours], r, target, verdict))
        else:
            rows.append((label, runs.get(kdl), runs.get(ours), None, target, "missing"))
    for name, entry in runs.items():  # every full update against KDL's estimator, informative
        if name.startswith(FULL_PREFIX) and name != PAIRS[-1][2] and "BM_ExtWrench_Kdl" in runs:
            label = "full update " + name[len(FULL_PREFIX):] + " vs JntToExtWrench"
            rows.append((label, runs["BM_ExtWrench_Kdl"], entry,
                         runs["BM_ExtWrench_Kdl"]["ns"] / entry["ns"], None, ""))
    return rows


def self_rows(runs):
    rows = []
    for label, before, after, target in SELF_PAIRS:
        if before in runs and after in runs:
            r = runs[before]["ns"] / runs[after]["ns"]
            verdict = "" if target is None else ("met" if r >= target else "NOT MET")
            rows.append((label, runs[before], runs[after], r, target, verdict))
        else:
            rows.append((label, runs.get(before), runs.get(after), None, target, "missing"))
    return rows


def print_console(context, runs, use_real):
    print(f"\nextwrench vs KDL ({'wall' if use_real else 'CPU'} time, medians); "
          f"robot: {context.get('robot', '?')}")
    for label, kdl, ours, r, target, verdict in ratio_rows(runs):
        if r is None:
            print(f"  {label:<68} missing")
            continue
        t = f" (target ≥ {target:g}×: {verdict})" if target else ""
        print(f"  {label:<68} {fmt_ns(kdl['ns']):>10} / {fmt_ns(ours['ns']):>10} = "
              f"{r:5.1f}×{t}")
    for label, before, after, r, target, verdict in self_rows(runs):
        if r is None:
            print(f"  {label:<68} missing")
            continue
        t = f" (target ≥ {target:g}×: {verdict})" if target else ""
        print(f"  {label:<68} {fmt_ns(before['ns']):>10} / {fmt_ns(after['ns']):>10} = "
              f"{r:5.1f}×{t}")
    for name, e in runs.items():
        if name.startswith(LATENCY_PREFIX):
            print(f"  latency {name[len(LATENCY_PREFIX):]}: median {e['p50_ns']:.0f} ns, "
                  f"min {e['min_ns']:.0f}, p99 {e['p99_ns']:.0f}, p99.9 {e['p999_ns']:.0f}, "
                  f"max {e['max_ns']:.0f} ns over {e['calls']:.0f} calls")


def print_markdown(context, runs, use_real):
    clock = "wall-clock" if use_real else "CPU"
    print(f"Machine: {context.get('num_cpus', '?')} CPUs at {context.get('mhz_per_cpu', '?')} MHz, "
          f"{context.get('compiler', '?')}, {context.get('flags', '?')}; "
          f"run {context.get('date', '?')}, load average "
          f"{', '.join(f'{x:.2f}' for x in context.get('load_avg', []))}; robot: "
          f"{context.get('robot', '?')}.\n")
    print(f"| benchmark | median ({clock}) | allocations / call |")
    print("|---|---:|---:|")
    for name, e in runs.items():
        if not name.startswith(LATENCY_PREFIX):
            print(f"| `{name}` | {fmt_ns(e['ns'])} | {fmt_allocs(e)} |")
    print("\n| comparison | KDL | ours | KDL / ours | target |")
    print("|---|---:|---:|---:|---|")
    for label, kdl, ours, r, target, verdict in ratio_rows(runs):
        if r is None:
            print(f"| {label} | – | – | – | missing |")
            continue
        t = f"≥ {target:g}× ({verdict})" if target else ""
        print(f"| {label} | {fmt_ns(kdl['ns'])} | {fmt_ns(ours['ns'])} | **{r:.1f}×** | {t} |")
    print("\n| our own speed-up | before | now | before / now | target |")
    print("|---|---:|---:|---:|---|")
    for label, before, after, r, target, verdict in self_rows(runs):
        if r is None:
            print(f"| {label} | – | – | – | missing |")
            continue
        t = f"≥ {target:g}× ({verdict})" if target else ""
        print(f"| {label} | {fmt_ns(before['ns'])} | {fmt_ns(after['ns'])} | **{r:.1f}×** | {t} |")
    lat = [(n, e) for n, e in runs.items() if n.startswith(LATENCY_PREFIX)]
    if lat:
        print("\n| latency per call (steady clock) | calls | min | median | p99 | p99.9 | max |")
        print("|---|---:|---:|---:|---:|---:|---:|")
        for name, e in lat:
            print(f"| `{name}` | {e['calls']:.0f} | {e['min_ns']:.0f} ns | {e['p50_ns']:.0f} ns | "
                  f"{e['p99_ns']:.0f} ns | {e['p999_ns']:.0f} ns | {e['max_ns']:.0f} ns |")


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    path = args[0] if args else "build/bench.json"
    use_real = "--real" in argv
    context, runs = load(path, use_real)
    if "--markdown" in argv:
        print_markdown(context, runs, use_real)
    else:
        print_console(context, runs, use_real)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
