#!/usr/bin/env python3
"""Issue 24's validation on real data (docs/thermal.md, "Validation on the Paderborn bench"): profile A of the
Paderborn bench with its magnet sensor (`pm`) hidden from every tool — the thermal network fitted on the
heat-up (t <= 4400 s), the cool-down judged against the measured `pm` and `stator_winding`:

  (a) the model alone (open loop from the soaked start: `rpem thermal fit`'s predictions),
  (b) RPEM alone (the magnet law's inverse of psi_m; the winding's of the held r_s),
  (c) fused (`rpem estimate --thermal`), twice: without the winding sensor in the judged part (the honest
      test: nothing of the judged winding reaches the filter) and with it (circular for the winding).

  paderborn_validation.py --rpem BIN --source-dir DIR --work DIR [--json OUT.json]

Prints the table and asserts the bounds below; exit 1 on a miss. Only the standard library.

Bounds. Issue 24's acceptance is fused <= 3 K RMS and <= 6 K worst on both, the 2-sigma band covering >= 90 %
of the measured points. What is met is asserted as that; what is not (docs/thermal.md says why) is asserted
as the figures measured, two-sided, so that a change in either direction is seen."""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

SPLIT_S = 4400.0  # the load change: heat-up before, cool-down after (docs/diagnose.md)


def run(cmd):
    print("+ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print(r.stdout, end="")
    if r.returncode != 0:
        sys.exit(f"command failed with exit code {r.returncode}")


def stats(pairs):
    e = [a - b for a, b in pairs if not (math.isnan(a) or math.isnan(b))]
    return {"n": len(e), "rms_K": math.sqrt(sum(x * x for x in e) / len(e)), "worst_K": max(abs(x) for x in e),
            "mean_K": sum(e) / len(e)}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rpem", required=True)
    ap.add_argument("--source-dir", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--json")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    src = os.path.join(a.source_dir, "data/paderborn-motor-temperature/profile_A_every5th.csv")
    cfg = os.path.join(a.source_dir, "config/paderborn-pmsm.yaml")
    start = os.path.join(a.source_dir, "config/paderborn-thermal.yaml")
    conv = os.path.join(a.source_dir, "scripts/paderborn_to_drive_log.py")
    w = lambda name: os.path.join(a.work, name)
    # The logs the tools see: no T_magnet; the honest one without T_winding after the split.
    run([sys.executable, conv, src, w("full.csv"), "--pole-pairs", "4", "--averaged", "--coolant", "--no-magnet"])
    run([sys.executable, conv, src, w("honest.csv"), "--pole-pairs", "4", "--averaged", "--coolant", "--no-magnet",
         "--winding-until-s", str(SPLIT_S)])
    for log in ("full.csv", "honest.csv"):
        with open(w(log)) as f:
            if "T_magnet" in f.readline():
                sys.exit(f"{log} carries the magnet sensor")
    run([a.rpem, "thermal", "fit", "--log", w("full.csv"), "--config", cfg, "--start", start, "--fit-until-s", str(SPLIT_S),
         "--out", w("thermal.yaml"), "--report", w("fit")])
    run([a.rpem, "estimate", "--log", w("honest.csv"), "--config", cfg, "--thermal", w("thermal.yaml"), "--out", w("honest_est.csv")])
    run([a.rpem, "estimate", "--log", w("full.csv"), "--config", cfg, "--thermal", w("thermal.yaml"), "--out", w("full_est.csv")])

    truth = list(csv.DictReader(open(src)))
    model = list(csv.DictReader(open(w("fit/predictions.csv"))))
    honest = list(csv.DictReader(open(w("honest_est.csv"))))
    full = list(csv.DictReader(open(w("full_est.csv"))))
    if not (len(truth) == len(honest) == len(full) == len(model) + 1):
        sys.exit(f"row counts differ: {len(truth)} {len(honest)} {len(full)} {len(model)}")
    result = {}
    for node, column in (("magnet", "pm"), ("winding", "stator_winding")):
        r = {}
        judged = [k for k in range(len(truth)) if float(honest[k]["t"]) > SPLIT_S]
        T = lambda k: float(truth[k][column])
        # model's rows are the filter's steps, one per log row from the second on
        r["model"] = stats([(float(model[k - 1][f"T_{node}_model"]), T(k)) for k in judged])
        r["rpem"] = stats([(float(honest[k][f"T_{node}_rpem"]), T(k)) for k in judged])
        for name, est in (("fused", honest), ("fused_with_sensor", full)):
            s = stats([(float(est[k][f"T_{node}"]), T(k)) for k in judged])
            s["cover_2sigma"] = sum(abs(float(est[k][f"T_{node}"]) - T(k)) <= 2.0 * float(est[k][f"sigma_{node}"])
                                    for k in judged) / len(judged)
            r[name] = s
        result[node] = r
    fit = json.load(open(w("fit/fit.json")))
    result["fit"] = {"signals": fit["signals"], "process_noise_K2_per_s": fit["process_noise_K2_per_s"]}

    print(f"\ncool-down (t > {SPLIT_S:g} s, {result['magnet']['fused']['n']} rows) against pm and stator_winding:")
    print(f"{'':28s} {'RMS [K]':>8s} {'worst [K]':>9s} {'mean [K]':>9s} {'2σ cover':>9s}")
    for node in ("magnet", "winding"):
        for name in ("model", "rpem", "fused", "fused_with_sensor"):
            s = result[node][name]
            cover = f"{100 * s['cover_2sigma']:8.1f}%" if "cover_2sigma" in s else ""
            print(f"{node + ' ' + name:28s} {s['rms_K']:8.2f} {s['worst_K']:9.2f} {s['mean_K']:+9.2f} {cover:>9s}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=2)

    failures = []

    def check(what, value, lo, hi):
        ok = lo <= value <= hi
        print(f"{'ok  ' if ok else 'MISS'} {what}: {value:.3f} in [{lo}, {hi}]")
        if not ok:
            failures.append(what)

    m, wd = result["magnet"], result["winding"]
    # Met: the acceptance's coverage, on both; the winding with its sensor (circular, stated).
    check("magnet fused 2σ coverage (acceptance >= 0.9)", m["fused"]["cover_2sigma"], 0.9, 1.0)
    check("winding fused 2σ coverage, no sensor in the cool-down (acceptance >= 0.9)", wd["fused"]["cover_2sigma"], 0.9, 1.0)
    check("winding fused with its sensor: RMS (acceptance <= 3 K; circular)", wd["fused_with_sensor"]["rms_K"], 0.0, 3.0)
    check("winding fused with its sensor: worst (acceptance <= 6 K; circular)", wd["fused_with_sensor"]["worst_K"], 0.0, 6.0)
    # Not met (docs/thermal.md): the figures as measured, two-sided.
    check("magnet fused RMS [K] (acceptance 3; measured 3.2)", m["fused"]["rms_K"], 2.5, 4.0)
    check("magnet fused worst [K] (acceptance 6; measured 9.5)", m["fused"]["worst_K"], 7.0, 12.0)
    check("winding fused RMS without its sensor [K] (acceptance 3; measured 38)", wd["fused"]["rms_K"], 25.0, 50.0)
    # What the fusion must never do: be worse than what it fuses.
    check("magnet: fused RMS minus RPEM alone [K]", m["fused"]["rms_K"] - m["rpem"]["rms_K"], -3.0, 0.3)
    check("winding: fused RMS minus the model alone, no sensor [K]", wd["fused"]["rms_K"] - wd["model"]["rms_K"], -60.0, 0.0)
    if failures:
        print(f"{len(failures)} bound(s) missed: " + "; ".join(failures))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
