#!/usr/bin/env python3
"""Issue 24's second validation (docs/thermal.md, "Validation on the independent plant"): the independent
three-node thermal plant (tests/independent_thermal/, its forms not ours, written without reading ours) on a
seeded two-hour drive cycle, its coolant loop heating with the load; rpem's two-node network fitted on the first
5400 s, the last 1800 s judged against the plant's true winding and magnet (rotor) temperatures — the fused
estimate without the winding sensor in the judged part and with it, beside the model alone and RPEM alone.
Then the same plant without the T_coolant column: the stated failure mode (a constant coolant assumed).

  independent_validation.py --rpem BIN --plant BIN --source-dir DIR --work DIR [--json OUT.json]

Prints the tables and asserts the bounds below (two-sided: the figures measured; the acceptance's where met)."""
import argparse
import csv
import json
import os
import sys

from thermal_judge import Bounds, judge, print_table, read, run

SEED = 7
DURATION_S = 7200.0
SPLIT_S = 5400.0


def without_winding_after(src, dst, split_s):
    """The log with T_winding 'nan' (not reported) after split_s: nothing of the judged winding reaches the filter."""
    with open(src, newline="") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    t, w = header.index("t"), header.index("T_winding")
    with open(dst, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(header)
        for r in rows[1:]:
            if float(r[t]) > split_s:
                r[w] = "nan"
            out.writerow(r)


def validate(a, tag, extra):
    w = lambda name: os.path.join(a.work, f"{tag}_{name}")
    cfg = os.path.join(a.source_dir, "config/paderborn-pmsm.yaml")
    run([a.plant, "--config", cfg, "--seed", str(SEED), "--duration-s", str(DURATION_S), "--rate-Hz", "2", "--averaged",
         "--out", w("log.csv"), "--truth", w("truth.csv"), "--parameters", w("plant.json")] + extra)
    without_winding_after(w("log.csv"), w("honest.csv"), SPLIT_S)
    fit_out = run([a.rpem, "thermal", "fit", "--log", w("log.csv"), "--config", cfg, "--fit-until-s", str(SPLIT_S),
                   "--out", w("thermal.yaml"), "--report", w("fit")])
    run([a.rpem, "estimate", "--log", w("honest.csv"), "--config", cfg, "--thermal", w("thermal.yaml"), "--out", w("honest_est.csv")])
    run([a.rpem, "estimate", "--log", w("log.csv"), "--config", cfg, "--thermal", w("thermal.yaml"), "--out", w("full_est.csv")])
    truth = read(w("truth.csv"))
    estimates = {"fused": read(w("honest_est.csv")), "fused_with_sensor": read(w("full_est.csv"))}
    result = {node: judge(truth, f"T_{node}", estimates, read(w("fit/predictions.csv")), node, SPLIT_S)
              for node in ("magnet", "winding")}
    print_table(f"{tag}: t > {SPLIT_S:g} s against the plant's true temperatures", result,
                ("model", "rpem", "fused", "fused_with_sensor"))
    result["plant"] = json.load(open(w("plant.json")))["parameters"]
    result["fit_said_coolant_constant"] = "has no T_coolant column" in fit_out
    return result


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rpem", required=True)
    ap.add_argument("--plant", required=True)
    ap.add_argument("--source-dir", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--json")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    coolant = validate(a, "coolant", [])
    blind = validate(a, "no_coolant", ["--no-coolant"])
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"coolant": coolant, "no_coolant": blind}, f, indent=2)

    b = Bounds()
    m, wd = coolant["magnet"], coolant["winding"]
    # With the coolant column. Met: the 2σ coverage of the winding; the winding with its sensor (circular).
    b.check("winding fused 2σ coverage, no sensor in the judged part (acceptance >= 0.9)", wd["fused"]["cover_2sigma"], 0.9, 1.0)
    b.check("winding fused with its sensor: RMS (acceptance <= 3 K; circular)", wd["fused_with_sensor"]["rms_K"], 0.0, 3.0)
    # The model alone extrapolates here (a drive cycle excites every loss): measured 3.7 K RMS, 11.9 K worst.
    b.check("winding model alone RMS [K] (measured 3.7)", wd["model"]["rms_K"], 2.0, 6.0)
    # Not met (docs/thermal.md): the figures measured, two-sided. The magnet's law assumes NdFeB's −0.12 %/K,
    # the plant's magnet has −0.096 %/K: its rise reads 20 % short; the winding without its sensor takes the
    # R_s observations of standstills with little current (their excitation is not judged yet).
    b.check("winding fused RMS, no sensor [K] (acceptance 3; measured 6.6)", wd["fused"]["rms_K"], 4.0, 9.0)
    b.check("magnet fused RMS [K] (acceptance 3; measured 14.5)", m["fused"]["rms_K"], 10.0, 18.0)
    b.check("magnet fused 2σ coverage (acceptance 0.9; measured 0.84)", m["fused"]["cover_2sigma"], 0.7, 0.95)
    # Without the coolant column: the fit says it assumes a constant coolant, and the model is worse for it.
    n = blind["winding"]
    b.check("no coolant column: the fit states the constant coolant", 1.0 if blind["fit_said_coolant_constant"] else 0.0, 1.0, 1.0)
    b.check("no coolant column: model alone's winding RMS minus with it [K] (measured +1.9)",
            n["model"]["rms_K"] - wd["model"]["rms_K"], 0.5, 6.0)
    return b.exit_code()


if __name__ == "__main__":
    sys.exit(main())
