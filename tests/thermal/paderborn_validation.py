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
import json
import os
import re
import sys

from thermal_judge import Bounds, arguments, judge, print_table, read, run, write_json

SPLIT_S = 4400.0  # the load change: heat-up before, cool-down after (docs/diagnose.md)


def main() -> int:
    a = arguments(__doc__)
    src = os.path.join(a.source_dir, "data/paderborn-motor-temperature/profile_A_every5th.csv")
    cfg = os.path.join(a.source_dir, "config/paderborn-pmsm.yaml")
    start = os.path.join(a.source_dir, "config/paderborn-thermal.yaml")
    conv = os.path.join(a.source_dir, "scripts/paderborn_to_drive_log.py")
    w = lambda name: os.path.join(a.work, name)
    # The logs the tools see: no T_magnet; the honest one without T_winding after the split.
    run([sys.executable, conv, src, w("full.csv"), "--pole-pairs", "4", "--sample-period-s", "2.5", "--averaged", "--coolant", "--no-magnet"])
    run([sys.executable, conv, src, w("honest.csv"), "--pole-pairs", "4", "--sample-period-s", "2.5", "--averaged", "--coolant", "--no-magnet",
         "--winding-until-s", str(SPLIT_S)])
    for log in ("full.csv", "honest.csv"):
        with open(w(log)) as f:
            if "T_magnet" in f.readline():
                sys.exit(f"{log} carries the magnet sensor")
    run([a.rpem, "thermal", "fit", "--log", w("full.csv"), "--config", cfg, "--start", start, "--fit-until-s", str(SPLIT_S),
         "--out", w("thermal.yaml"), "--report", w("fit")])
    with open(w("thermal.yaml")) as f:
        if "copper law takes" in f.read():  # the start states R_s's temperature: no assumption to note
            sys.exit("thermal.yaml notes an assumed copper reference although the start gives reference_C")
    run([a.rpem, "estimate", "--log", w("honest.csv"), "--config", cfg, "--thermal", w("thermal.yaml"), "--out", w("honest_est.csv")])
    run([a.rpem, "estimate", "--log", w("full.csv"), "--config", cfg, "--thermal", w("thermal.yaml"), "--out", w("full_est.csv")])

    truth = read(src)
    model = read(w("fit/predictions.csv"))
    estimates = {"fused": read(w("honest_est.csv")), "fused_with_sensor": read(w("full_est.csv"))}
    if not all(len(e) == len(truth) for e in estimates.values()):
        sys.exit("the estimate CSVs do not have a row per profile row")
    result = {node: judge(truth, column, estimates, model, node, SPLIT_S)
              for node, column in (("magnet", "pm"), ("winding", "stator_winding"))}
    print_table(f"cool-down (t > {SPLIT_S:g} s, {result['magnet']['fused']['n']} rows) against pm and stator_winding:",
                result, ("model", "rpem", "fused", "fused_with_sensor"))
    # The figure (docs/thermal.md, "Figures"): measured pm only here, for the plot; its coverage is computed
    # apart (interpolated at the measured times) and must agree with the table's.
    run([sys.executable, conv, src, w("measured.csv"), "--pole-pairs", "4", "--sample-period-s", "2.5", "--averaged", "--coolant"])
    fig_out = run([a.rpem, "figures", "--out", w("figures"), "--thermal-estimate", w("honest_est.csv"),
                   "--measured", w("measured.csv"), "--judged-after-s", str(SPLIT_S)])
    fig_cover = re.search(r"magnet ([0-9.]+) %, winding ([0-9.]+) %", fig_out)
    fit = json.load(open(w("fit/fit.json")))
    result["fit"] = {"signals": fit["signals"], "process_noise_K2_per_s": fit["process_noise_K2_per_s"]}
    write_json(a.json, result)

    bounds = Bounds()
    check = bounds.check
    m, wd = result["magnet"], result["winding"]
    # Met: the acceptance's coverage, on both; the winding with its sensor (circular, stated).
    check("winding fused 2σ coverage, no sensor in the cool-down (acceptance >= 0.9)", wd["fused"]["cover_2sigma"], 0.9, 1.0)
    check("magnet fused 2σ coverage (acceptance >= 0.9)", m["fused"]["cover_2sigma"], 0.9, 1.0)
    check("winding fused with its sensor: RMS (acceptance <= 3 K; circular)", wd["fused_with_sensor"]["rms_K"], 0.0, 3.0)
    check("winding fused with its sensor: worst (acceptance <= 6 K; circular)", wd["fused_with_sensor"]["worst_K"], 0.0, 6.0)
    # Not met (docs/thermal.md): the figures as measured, two-sided. The magnet's moved to 9.1 K RMS, 17.2 K
    # worst, 76 % cover when the regimes merged, while config/paderborn-pmsm.yaml made the 2.5 s rows one chain
    # whose run-up the classifier took for noise (docs/thermal.md, "Since the regimes merge"); with the rows
    # standalone: 3.26 K RMS, 11.4 K worst (right after the load change), 100 %; with the bilinear calibration
    # term (eq. 14.10a, 2026-11-27) 3.07 K RMS, 7.95 K worst: the worst's band scaled by 7.95/11.4. With NdFeB's
    # coefficient σ holding its whole range (eq. 14.11a, 16.7 % from 12.0 %) 2.87 K RMS (met from here: asserted
    # one-sided) and 6.79 K worst: the worst's band scaled by 6.79/7.95.
    check("magnet fused RMS (acceptance <= 3 K; measured 2.87)", m["fused"]["rms_K"], 0.0, 3.0)
    check("magnet fused worst [K] (acceptance 6; measured 6.79)", m["fused"]["worst_K"], 5.36, 8.34)
    check("winding fused RMS without its sensor [K] (acceptance 3; measured 36.5)", wd["fused"]["rms_K"], 25.0, 50.0)
    # What the fusion must never do: be worse than what it fuses.
    check("magnet: fused RMS minus RPEM alone [K]", m["fused"]["rms_K"] - m["rpem"]["rms_K"], -3.0, 0.3)
    check("winding: fused RMS minus the model alone, no sensor [K]", wd["fused"]["rms_K"] - wd["model"]["rms_K"], -60.0, 0.0)
    check("figure's magnet 2σ coverage minus the table's", float(fig_cover.group(1)) / 100 - m["fused"]["cover_2sigma"], -0.01, 0.01)
    check("figure's winding 2σ coverage minus the table's", float(fig_cover.group(2)) / 100 - wd["fused"]["cover_2sigma"], -0.01, 0.01)
    return bounds.exit_code()


if __name__ == "__main__":
    sys.exit(main())
