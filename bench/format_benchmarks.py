#!/usr/bin/env python3
"""Formats Google Benchmark JSON files as Markdown tables (median and max of the repetitions)."""
import json
import sys

ALGORITHMS = {"0": "SGA", "1": "GNA", "2": "PhyInt"}
FIDELITIES = {"0": "switching (edge to edge)", "1": "switching (1 µs fixed plant step)", "2": "averaged"}


def label(name):
    parts = dict(p.split(":") for p in name.split("/")[1:] if ":" in p)
    if name.startswith("BM_EstimatorStep"):
        grad = "dynamic" if parts.get("dynamic_gradient") == "1" else "steady-state"
        return f"estimator step, {ALGORITHMS[parts['algorithm']]}, {grad} gradients"
    if name.startswith("BM_SimulateOneSecond"):
        fidelity = FIDELITIES[parts["fidelity"]]
        est = "with estimator" if parts.get("estimator") == "1" else "without estimator"
        return f"simulator, {fidelity}, {est}"
    if name.startswith("BM_SwitchingOverAveraged"):
        return "simulator, switching (edge to edge) over averaged, with estimator, same run"
    if name.startswith("BM_StepOverKernel"):
        return "estimator step (SGA, steady-state gradients) over the minimal SGA kernel, same run"
    if name.startswith("BM_SgaKernel"):
        return "minimal SGA kernel (tests/support/sga_kernel.hpp)"
    if name.startswith("BM_DiagnoseTwentySecondLog"):
        return "rpem diagnose, 20 s log at 8 kHz (read, diagnose, write report)"
    return name


def main(paths):
    context = None
    rows = {}
    for path in paths:
        with open(path) as f:
            data = json.load(f)
        context = data["context"]
        for b in data["benchmarks"]:
            if b.get("run_type") != "aggregate":
                continue
            base = b["run_name"]
            agg = b["aggregate_name"]
            rows.setdefault(base, {})[agg] = b
    print(f"Run: {context['date']}, {context['num_cpus']} CPUs at {context['mhz_per_cpu']} MHz, "
          f"rpem built Release (-O3)\n")
    print("| benchmark | median | max | unit / counter |")
    print("|---|---|---|---|")
    for base, aggs in rows.items():
        med = aggs.get("median")
        mx = aggs.get("max")
        if "ratio" in med:
            worst = mx["ratio"] if mx else float("nan")
            parts = ", ".join(f"{k} {med[k]:.3g}" for k in ("switching_x_real_time", "averaged_x_real_time",
                                                              "kernel_ns", "step_ns") if k in med)
            print(f"| {label(base)} | ratio {med['ratio']:.3f} | {worst:.3f} | median {parts} |")
        elif "x_real_time" in med:
            print(f"| {label(base)} | {med['x_real_time']:.0f}× real time | "
                  f"{aggs['min']['x_real_time'] if 'min' in aggs else med['x_real_time']:.0f}× (slowest) | wall {med['real_time']:.1f} ms per simulated s |")
        else:
            worst = mx["real_time"] if mx else float("nan")
            unit = med.get("time_unit", "ns")
            what = "per step" if unit == "ns" else "per run"
            print(f"| {label(base)} | {med['real_time']:.2f} {unit} | {worst:.2f} {unit} | {unit} {what} (max of {med['repetitions']} repetition means) |")


if __name__ == "__main__":
    main(sys.argv[1:])
