"""What the thermal validations share (docs/thermal.md, "Validation"): running the tools, judging estimate CSVs
against measured or true temperatures, and two-sided bounds. Only the standard library."""
import argparse
import csv
import json
import math
import os
import subprocess
import sys


def arguments(doc, extra=()):
    """The command line every validation takes (--rpem, --source-dir, --work, --json) and its own `extra`
    ((flag, add_argument's keywords) pairs), described by the first line of its `doc`; the work directory made."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    for flag, keywords in extra:
        ap.add_argument(flag, **keywords)
    for flag in ("--rpem", "--source-dir", "--work"):
        ap.add_argument(flag, required=True)
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    return a


def write_json(path, figures):
    """The figures for docs/thermal.md, where --json asked for them."""
    if path:
        with open(path, "w") as f:
            json.dump(figures, f, indent=1)


def run(cmd):
    """Runs a command, echoing it and its output; stops the validation if it fails."""
    print("+ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print(r.stdout, end="")
    if r.returncode != 0:
        sys.exit(f"command failed with exit code {r.returncode}")
    return r.stdout


def stats(pairs):
    """RMS, worst and mean of estimate − truth over the pairs that are both numbers."""
    e = [a - b for a, b in pairs if not (math.isnan(a) or math.isnan(b))]
    return {"n": len(e), "rms_K": math.sqrt(sum(x * x for x in e) / len(e)), "worst_K": max(abs(x) for x in e),
            "mean_K": sum(e) / len(e)}


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def judge(truth, truth_column, estimates, predictions, node, after_s):
    """The node's figures after `after_s`: the model alone (the fit's predictions.csv, matched by time), RPEM
    alone (T_<node>_rpem) and each fused estimate (T_<node>, with the share of rows inside ±2σ).
    `truth` rows align with the estimate rows; `estimates` maps a name to rows of an estimate CSV."""
    first = next(iter(estimates.values()))
    judged = [k for k in range(len(first)) if float(first[k]["t"]) > after_s]
    T = lambda k: float(truth[k][truth_column])
    model = {round(float(r["t"]), 6): float(r[f"T_{node}_model"]) for r in predictions}
    out = {"model": stats([(model[round(float(first[k]["t"]), 6)], T(k)) for k in judged
                           if round(float(first[k]["t"]), 6) in model]),
           "rpem": stats([(float(first[k][f"T_{node}_rpem"]), T(k)) for k in judged])}
    for name, est in estimates.items():
        s = stats([(float(est[k][f"t_{node}_fused_C"]), T(k)) for k in judged])
        s["cover_2sigma"] = sum(abs(float(est[k][f"t_{node}_fused_C"]) - T(k)) <= 2.0 * float(est[k][f"t_{node}_fused_sd_C"])
                                for k in judged) / len(judged)
        out[name] = s
    return out


def print_table(title, result, names):
    print(f"\n{title}")
    print(f"{'':34s} {'RMS [K]':>8s} {'worst [K]':>9s} {'mean [K]':>9s} {'2σ cover':>9s}")
    for node, r in result.items():
        for name in names:
            s = r[name]
            cover = f"{100 * s['cover_2sigma']:8.1f}%" if "cover_2sigma" in s else ""
            print(f"{node + ' ' + name:34s} {s['rms_K']:8.2f} {s['worst_K']:9.2f} {s['mean_K']:+9.2f} {cover:>9s}")


class Bounds:
    """Two-sided checks; a miss is printed and counted."""

    def __init__(self):
        self.failures = []

    def check(self, what, value, lo, hi):
        ok = lo <= value <= hi
        print(f"{'ok  ' if ok else 'MISS'} {what}: {value:.3f} in [{lo}, {hi}]")
        if not ok:
            self.failures.append(what)

    def exit_code(self):
        if self.failures:
            print(f"{len(self.failures)} bound(s) missed: " + "; ".join(self.failures))
            return 1
        return 0
