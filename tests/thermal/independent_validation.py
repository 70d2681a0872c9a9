#!/usr/bin/env python3
"""Issue 24's second validation (docs/thermal.md, "Validation on the independent plant"): the independent
three-node thermal plant (tests/independent_thermal/, its forms not ours, written without reading ours) with
rpem's two-node network fitted on the first part of each log and the rest judged against the plant's true
winding and magnet (rotor) temperatures — the fused estimate without the winding sensor in the judged part and
with it, beside the model alone and RPEM alone. The temperature laws the tools are given are the plant's own
coefficients (its parameters JSON: copper.alpha20_per_K, magnet.alpha20_per_K, referred to the references the
machine's values hold at), as a commissioning measurement would give them, and its winding sensor's time
constant (sensor.winding_tau_s: a sensor's step response, from its data sheet or a bath test), with the network's
winding node standing for that sensor's reading (`node: reading`, eq. 14.24); nothing else of the truth.

Cases (one per ctest, --case):
  profile_a     Paderborn profile A's operating points, constant coolant at 19.5 °C, the configuration's R_s and
                ψm referred to 119 °C and 112 °C as on the bench; fitted on t <= 4400 s (the heat-up).
  drive_cycle   a seeded two-hour drive cycle, the coolant loop heating with the load; fitted on t <= 5400 s.
  no_coolant    the drive cycle without its T_coolant column: the stated failure mode (a constant coolant is
                assumed; the fit says so, and the model is worse for it).
  sensor_lag    the drive cycle's first 4 200 s with no τ_s given: the fit finds the sensor's τ_s from the
                standstills where r̂s adapts (eq. 14.25–14.25d) and uses it; only the fit runs, nothing is judged
                but that τ_s against the plant's.

  independent_validation.py --case NAME --rpem BIN --plant BIN --source-dir DIR --work DIR [--json OUT.json]

Prints the table and asserts the bounds below (two-sided where the acceptance is not met: the figures measured)."""
import csv
import json
import os
import re
import sys

from thermal_judge import Bounds, arguments, judge, print_table, read, run, write_json

PROFILE = "tests/independent_thermal/profiles/paderborn_profile_a_like.csv"
CASES = {
    "profile_a": {"split_s": 4400.0,
                  "plant": ["--profile", PROFILE, "--coolant", "constant", "--set", "coolant.start_C=19.5",
                            "--set", "electrical.r_s_reference_C=119", "--set", "electrical.psi_m_reference_C=112",
                            "--duration-s", "7505", "--rate-Hz", "2", "--seed", "1"]},
    "drive_cycle": {"split_s": 5400.0, "plant": ["--duration-s", "7200", "--rate-Hz", "2", "--seed", "7"]},
    "no_coolant": {"split_s": 5400.0, "plant": ["--duration-s", "7200", "--rate-Hz", "2", "--seed", "7", "--no-coolant"]},
    # four standstill runs of ≥ 60 steps before 3 700 s (the fit's rule asks three)
    "sensor_lag": {"split_s": 3700.0, "plant": ["--duration-s", "4200", "--rate-Hz", "2", "--seed", "7"]},
}
# eq. 14.25's note: "… (eq. 14.25, N standstill runs …): X s, 95 % interval [L, U] s, … ; used, …"
SENSOR_LAG_NOTE = re.compile(r"eq\. 14\.25, (\d+) standstill runs[^:]*: ([-0-9.e+]+) s, 95 % interval "
                             r"\[([-0-9.e+inf]+), ([-0-9.e+inf]+)\] s[^;]*; (used|not used)")


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


def referred(alpha20, reference_C):
    """A linear law's coefficient per K referred from 20 °C to reference_C (the same line)."""
    return alpha20 / (1.0 + alpha20 * (reference_C - 20.0))


def start_yaml(parameters, path, sensor_lag=True):
    """The laws of the plant's materials about the references its R_s and ψm are given at, and (sensor_lag) its
    winding sensor's time constant with the winding node standing for the reading (eq. 14.24); no network."""
    p = parameters
    rc, mc = p["electrical.r_s_reference_C"], p["electrical.psi_m_reference_C"]
    with open(path, "w") as f:
        f.write("# the plant's material coefficients (its parameters JSON), referred to its references\nthermal:\n")
        f.write(f"  copper: {{r_s_ref_Ohm: {p['electrical.r_s_ref_Ohm']!r}, reference_C: {rc!r}, "
                f"coeff_per_K: {referred(p['copper.alpha20_per_K'], rc)!r}}}\n")
        f.write(f"  magnet_law: {{psi_m_ref_Wb: {p['electrical.psi_m_ref_Wb']!r}, reference_C: {mc!r}, "
                f"coeff_per_K: {referred(p['magnet.alpha20_per_K'], mc)!r}}}\n")
        if sensor_lag:
            f.write(f"  winding_sensor: {{sigma_K: 1, time_constant_s: {p['sensor.winding_tau_s']!r}, node: reading}}\n")
        else:
            f.write("  winding_sensor: {sigma_K: 1}\n")


def validate(a, case):
    c = CASES[case]
    split = c["split_s"]
    w = lambda name: os.path.join(a.work, f"{case}_{name}")
    cfg = os.path.join(a.source_dir, "config/paderborn-pmsm.yaml")
    plant = [x if not x.startswith("tests/") else os.path.join(a.source_dir, x) for x in c["plant"]]
    run([a.plant, "--config", cfg, "--averaged", "--out", w("log.csv"), "--truth", w("truth.csv"),
         "--parameters", w("plant.json")] + plant)
    parameters = json.load(open(w("plant.json")))["parameters"]
    start_yaml(parameters, w("start.yaml"), sensor_lag=case != "sensor_lag")
    if case == "sensor_lag":
        return sensor_lag_found(a, w, cfg, split, parameters)
    without_winding_after(w("log.csv"), w("honest.csv"), split)
    fit_out = run([a.rpem, "thermal", "fit", "--log", w("log.csv"), "--config", cfg, "--start", w("start.yaml"),
                   "--fit-until-s", str(split), "--out", w("thermal.yaml"), "--report", w("fit")])
    run([a.rpem, "estimate", "--log", w("honest.csv"), "--config", cfg, "--thermal", w("thermal.yaml"), "--out", w("honest_est.csv")])
    run([a.rpem, "estimate", "--log", w("log.csv"), "--config", cfg, "--thermal", w("thermal.yaml"), "--out", w("full_est.csv")])
    truth = read(w("truth.csv"))
    estimates = {"fused": read(w("honest_est.csv")), "fused_with_sensor": read(w("full_est.csv"))}
    result = {node: judge(truth, f"T_{node}", estimates, read(w("fit/predictions.csv")), node, split)
              for node in ("magnet", "winding")}
    print_table(f"{case}: t > {split:g} s against the plant's true temperatures", result,
                ("model", "rpem", "fused", "fused_with_sensor"))
    result["plant"] = parameters
    result["fit_said_coolant_constant"] = "has no T_coolant column" in fit_out
    return result


def sensor_lag_found(a, w, cfg, split, parameters):
    """The fit without a τ_s: what its eq. 14.25 note says and what it wrote to thermal.yaml."""
    out = run([a.rpem, "thermal", "fit", "--log", w("log.csv"), "--config", cfg, "--start", w("start.yaml"),
               "--fit-until-s", str(split), "--out", w("thermal.yaml")])
    m = SENSOR_LAG_NOTE.search(out)
    written = re.search(r"winding_sensor: \{[^}]*time_constant_s: ([-0-9.e+]+), node: reading", open(w("thermal.yaml")).read())
    result = {"plant": parameters, "truth_s": parameters["sensor.winding_tau_s"], "note": m is not None,
              "written_s": float(written.group(1)) if written else float("nan")}
    if m:
        result.update(runs=int(m.group(1)), tau_s=float(m.group(2)), lower_s=float(m.group(3)),
                      upper_s=float(m.group(4)), used=m.group(5) == "used")
    print(f"sensor_lag: {result}")
    return result


def check_sensor_lag(r, b):
    b.check("the fit's eq. 14.25 note is there", 1.0 if r["note"] else 0.0, 1.0, 1.0)
    if not r["note"]:
        return
    truth = r["truth_s"]
    b.check("standstill runs", r["runs"], 3, 1e9)
    b.check("τ_s used", 1.0 if r["used"] else 0.0, 1.0, 1.0)
    # Measured 5.11 s [4.26, 5.96] against 4.84 s (2026-12-06, eq. 14.25f); over eight plants the errors were −1.3…+5.2 %.
    b.check(f"τ_s within 10 % of the plant's {truth:.3f} s", r["tau_s"], 0.9 * truth, 1.1 * truth)
    b.check("the interval holds the plant's τ_s: lower end", r["lower_s"], 0.0, truth)
    b.check("the interval holds the plant's τ_s: upper end", r["upper_s"], truth, 1e9)
    b.check("thermal.yaml's τ_s is the estimate", r["written_s"], r["tau_s"] - 1e-5, r["tau_s"] + 1e-5)


def check(case, r, b):
    if case == "sensor_lag":
        check_sensor_lag(r, b)
        return
    m, wd = r["magnet"], r["winding"]
    if case == "no_coolant":
        b.check("no coolant column: the fit states the constant coolant", 1.0 if r["fit_said_coolant_constant"] else 0.0, 1.0, 1.0)
        b.check(f"no coolant column: winding model alone RMS [K] (measured {MEASURED[case]['wm']})", wd["model"]["rms_K"],
                *around(MEASURED[case]["wm"]))
        return
    expect = MEASURED[case]
    for node, s in (("magnet", m), ("winding", wd)):
        for what, key, bound in (("RMS", "rms_K", 3.0), ("worst", "worst_K", 6.0)):
            v = s["fused"][key]
            measured = expect[f"{node[0]}_{key}"]
            if measured <= bound:
                b.check(f"{node} fused {what} (acceptance <= {bound} K; measured {measured})", v, 0.0, bound)
            else:
                b.check(f"{node} fused {what} [K] (acceptance {bound}, not met; measured {measured})", v, *around(measured))
        # With the winding sensor kept (what the log has; eq. 14.24 since 2026-11-28): the acceptance on both.
        ws = s["fused_with_sensor"]
        b.check(f"{node} fused, winding sensor kept: RMS (acceptance <= 3 K)", ws["rms_K"], 0.0, 3.0)
        b.check(f"{node} fused, winding sensor kept: worst (acceptance <= 6 K)", ws["worst_K"], 0.0, 6.0)
        b.check(f"{node} fused, winding sensor kept: 2σ coverage (acceptance >= 0.9)", ws["cover_2sigma"], 0.9, 1.0)
        cover = expect[f"{node[0]}_cover"]
        if cover >= 0.9:
            b.check(f"{node} fused 2σ coverage (acceptance >= 0.9; measured {cover})", s["fused"]["cover_2sigma"], 0.9, 1.0)
        else:
            b.check(f"{node} fused 2σ coverage (acceptance 0.9, not met; measured {cover})", s["fused"]["cover_2sigma"],
                    cover - 0.1, min(1.0, cover + 0.1))


def around(v):
    """A two-sided band about a measured figure: ±30 % and at least ±0.5 K."""
    d = max(0.5, 0.3 * abs(v))
    return (max(0.0, v - d), v + d)


# The figures measured (docs/thermal.md, "Validation on the independent plant"), asserted two-sided where the
# acceptance is not met so that a change either way is seen.
MEASURED = {
    # profile_a's winding since the regimes merge: 9.10 K RMS, 10.6 K worst, cover 0.967 (on the thermal branch
    # alone 4.73, 9.63, 0.984): 3 of 15 011 windows now excite R_s (docs/thermal.md, "Since the regimes merge").
    # The bilinear calibration term (eq. 14.10a, 2026-11-27) took the winding to 4.49 K RMS and the drive cycle's
    # magnet to 3.21 K RMS, 8.02 K worst (from 4.83, 11.6 on its parent; docs/thermal.md, "What the fused worst
    # error is made of").
    # The Gauss–Markov disturbance (eq. 14.19, τ_d per node by the likelihood, 2026-11-27) took profile_a's
    # winding to 2.09 K RMS (within the acceptance: asserted one-sided from here; docs/thermal.md, "A Gauss–Markov
    # disturbance").
    # NdFeB's coefficient σ holding its whole range (eq. 14.11a: 16.7 % from 12.0 %, 2026-11-27) moved profile_a's
    # magnet 0.18 → 1.07 K RMS (within the acceptance), its winding's worst 9.41 → 8.77 K, the drive cycle's magnet
    # 3.20 / 8.02 → 3.19 / 7.74 K and its winding 7.69 / 21.8 → 6.31 / 17.1 K (docs/thermal.md, "The magnet
    # coefficient's σ over NdFeB's whole range").
    # Convection that grows with speed (eq. 14.1b: the magnet's conductances to the coolant and across the gap, 2026-11-27)
    # took the drive cycle's magnet to 2.82 K RMS (within the acceptance: asserted one-sided from here), 8.42 K worst,
    # its winding to 5.78 / 16.3 K (docs/thermal.md, "Convection that grows with speed").
    # The winding node standing for its sensor's reading, the sensor's τ_s commissioned (eq. 14.24, 2026-11-28):
    # profile_a's sensorless winding 2.15 / 8.81 → 2.49 / 6.96 K, the drive cycle's magnet 2.82 / 8.42 → 2.44 /
    # 5.43 K (within the acceptance: asserted one-sided from here); the sensor-kept rows meet every bound
    # (docs/thermal.md, "The winding node as the sensor's reading").
    "profile_a": {"m_rms_K": 1.07, "m_worst_K": 1.46, "w_rms_K": 2.49, "w_worst_K": 6.96, "m_cover": 1.0, "w_cover": 0.986},
    "drive_cycle": {"m_rms_K": 2.44, "m_worst_K": 5.43, "w_rms_K": 5.78, "w_worst_K": 16.0, "m_cover": 1.0, "w_cover": 1.0},
    "no_coolant": {"wm": 5.45},  # the drive cycle's with its coolant column: 3.57
}


def main() -> int:
    a = arguments(__doc__, (("--case", {"required": True, "choices": sorted(CASES)}), ("--plant", {"required": True})))
    r = validate(a, a.case)
    write_json(a.json, r)
    b = Bounds()
    check(a.case, r, b)
    return b.exit_code()


if __name__ == "__main__":
    sys.exit(main())
