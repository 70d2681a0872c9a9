#!/usr/bin/env python3
"""The post-step rise of psi_row on the Paderborn bench's profile A, placed (docs/thermal.md, "The post-step
rise on Paderborn (2026-11-27)"; docs/derivations.md eq. 14.16). Reads the data and the machine constants,
prints every figure that section quotes. Only the standard library; an analysis, not a tool.

  paderborn_poststep_rise.py [--source-dir DIR] [--estimate EST.csv]

--estimate: `rpem estimate --thermal`'s CSV of the same rows (tests/thermal/paderborn_validation.py leaves it as
honest_est.csv in its work directory); then also what the fused magnet's worst error is made of.

psi_row = (u_q - R_s(T_w)*i_q - w*L_d*i_d)/w is each row's steady-state solution of the q row (w electrical,
R_s at the winding sensor's temperature), which `rpem estimate`'s psi_m follows to 0.01 % on these rows.
The window is 4407.5 -> 4480 s, each end the mean of 5 rows (4402.5-4412.5 s: the first rows after the load
change whose voltage has settled; 4475-4485 s: the middle of the worst fused error). Events: the run-up (load
on at ~10-15 s) and the load change at 4395 s, the profile's only two changes of operating point."""
import argparse
import math
import os
import re

PERIOD_S = 2.5
ALPHA_CU_PER_K = 0.00393  # copper (core/include/rpem/core/thermal.hpp, kCopper)
WINDOW = (4407.5, 4480.0)
STEP_S = 4395.0  # the first row of the load change
RUNUP_S = 12.5  # the run-up's load rows: i_d -119 A at 10 s, -179 A at 12.5 s, -191 A at 15 s
RUNUP_FIT = (17.5, 600.0)
STEP_FIT = (4402.5, 5000.0)


def config_value(path, key):
    with open(path) as f:
        m = re.search(r"^\s*" + re.escape(key) + r":\s*([-0-9.eE+]+)", f.read(), re.M)
    return float(m.group(1))


def solve(a, b):
    """Gaussian elimination with partial pivoting (a small dense system)."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(c + 1, n):
            f = m[r][c] / m[c][c]
            for k in range(c, n + 1):
                m[r][k] -= f * m[c][k]
    x = [0.0] * n
    for r in range(n - 1, -1, -1):
        x[r] = (m[r][n] - sum(m[r][k] * x[k] for k in range(r + 1, n))) / m[r][r]
    return x


def lstsq(cols, y):
    """Least squares y ~ sum c_j*cols_j; returns (coefficients, residuals)."""
    a = [[sum(p * q for p, q in zip(ci, cj)) for cj in cols] for ci in cols]
    b = [sum(p * q for p, q in zip(ci, y)) for ci in cols]
    c = solve(a, b)
    r = [yy - sum(cj * col[k] for cj, col in zip(c, cols)) for k, yy in enumerate(y)]
    return c, r


def lag(x, tau_s):
    """First-order lag, exact for a signal held over each row."""
    a = math.exp(-PERIOD_S / tau_s)
    y, out = x[0], []
    for v in x:
        y = a * y + (1 - a) * v
        out.append(y)
    return out


def lead(x, tau_s):
    """x + tau*dx/dt, the derivative a central difference over +-4 rows (20 s)."""
    n = len(x)
    return [x[k] + tau_s * (x[min(k + 4, n - 1)] - x[max(k - 4, 0)]) / (PERIOD_S * (min(k + 4, n - 1) - max(k - 4, 0)))
            for k in range(n)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--source-dir", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--estimate", help="rpem estimate --thermal's CSV of profile A (honest_est.csv)")
    a = ap.parse_args()
    cfg = os.path.join(a.source_dir, "config/paderborn-pmsm.yaml")
    thermal = os.path.join(a.source_dir, "config/paderborn-thermal.yaml")
    p = config_value(cfg, "pole_pairs")
    l_d, l_q, r_cfg = config_value(cfg, "l_d_H"), config_value(cfg, "l_q_H"), config_value(cfg, "r_s_Ohm")
    with open(thermal) as f:
        r_ref, t_ref = (float(v) for v in re.search(r"r_s_ref_Ohm:\s*([0-9.]+),\s*reference_C:\s*([0-9.]+)",
                                                    f.read()).groups())
    src = os.path.join(a.source_dir, "data/paderborn-motor-temperature/profile_A_every5th.csv")
    with open(src) as f:
        head = f.readline().strip().split(",")
        cols = {h: [] for h in head}
        for line in f:
            for h, v in zip(head, line.strip().split(",")):
                cols[h].append(float(v))
    n = len(cols["pm"])
    t = [k * PERIOD_S for k in range(n)]
    w = [s * 2 * math.pi / 60 * p for s in cols["motor_speed"]]
    i_d, i_q, u_d, u_q, pm = cols["i_d"], cols["i_q"], cols["u_d"], cols["u_q"], cols["pm"]
    tw = cols["stator_winding"]
    r_w = [r_ref * (1 + ALPHA_CU_PER_K * (x - t_ref)) for x in tw]
    at_speed = [x > 200 for x in w]
    psi = [(u_q[k] - r_w[k] * i_q[k] - w[k] * l_d * i_d[k]) / w[k] if at_speed[k] else float("nan") for k in range(n)]
    idx = lambda s: int(round(s / PERIOD_S))
    m5 = lambda x, s: sum(x[idx(s) - 2:idx(s) + 3]) / 5
    d5 = lambda x: m5(x, WINDOW[1]) - m5(x, WINDOW[0])
    rows = lambda lo, hi: [k for k in range(n) if at_speed[k] and lo <= t[k] <= hi]

    # The law's slope: psi_row against pm over the profile at speed from 20 s (the oracle of "Since the regimes
    # merge"), and the tools' -0.12 %/K about the same psi at 20 C.
    sel = rows(20.0, t[-1])
    (c0, slope), _ = lstsq([[1.0] * len(sel), [pm[k] for k in sel]], [psi[k] for k in sel])
    psi20 = c0 + 20 * slope
    slopes = {"fitted": slope, "tools' -0.12 %/K": -0.0012 * psi20}
    print(f"constants: p {p:g}, L_d {l_d * 1e6:.1f} uH, L_q {l_q * 1e6:.1f} uH, R_s {r_ref} Ohm at {t_ref:g} C,"
          f" alpha_cu {ALPHA_CU_PER_K}/K")
    print(f"law, psi_row on pm (t >= 20 s, {len(sel)} rows): {psi20 * 1e3:.2f} mWb at 20 C, slope"
          f" {slope * 1e6:.1f} uWb/K ({100 * slope / psi20:.4f} %/K); -0.12 %/K is {-0.0012 * psi20 * 1e6:.1f} uWb/K")

    print(f"\n1. the rise, {WINDOW[0]:g} -> {WINDOW[1]:g} s (5-row means)")
    dpsi = d5(psi)
    w0 = m5(w, WINDOW[0])
    terms = {"u_q/w": d5([u / x if x > 200 else 0.0 for u, x in zip(u_q, w)]),
             "-L_d*i_d": -l_d * d5(i_d),
             "-R_s(T_w)*i_q/w": -d5([r * i / x if x > 200 else 0.0 for r, i, x in zip(r_w, i_q, w)])}
    print(f"   psi_row {dpsi * 1e3:+.3f} mWb = " + " + ".join(f"{k} {v * 1e3:+.3f}" for k, v in terms.items()))
    print(f"   i_d {m5(i_d, WINDOW[0]):.2f} -> {m5(i_d, WINDOW[1]):.2f} A ({d5(i_d):+.2f} A),"
          f" i_q {m5(i_q, WINDOW[0]):.2f}"
          f" -> {m5(i_q, WINDOW[1]):.2f} A, u_q {m5(u_q, WINDOW[0]):.2f} -> {m5(u_q, WINDOW[1]):.2f} V,"
          f" |u| {m5([math.hypot(x, y) for x, y in zip(u_d, u_q)], WINDOW[0]):.2f} ->"
          f" {m5([math.hypot(x, y) for x, y in zip(u_d, u_q)], WINDOW[1]):.2f} V")
    k0, k1 = idx(4400), idx(4480)
    print(f"   single rows 4400 -> 4480 s: {(psi[k1] - psi[k0]) * 1e3:+.3f} mWb, of which the 4400 s row's settling"
          f" (to the window's start) {(m5(psi, WINDOW[0]) - psi[k0]) * 1e3:+.3f} mWb; at 4400 s u_q {u_q[k0]:.2f} V,"
          f" i_q {i_q[k0]:.2f} A")
    sp = [k for k in rows(20.0, t[-1]) if not STEP_S - 0.1 < t[k] < WINDOW[0] - 5]
    mags = [math.hypot(u_d[k], u_q[k]) for k in sp]
    print(f"   |u| at speed from 20 s but the step's rows 4395-4400 s: {min(mags):.1f}-{max(mags):.1f} V;"
          f" f_el {cols['motor_speed'][k1] / 60 * p:.0f} Hz,"
          f" |i| before the step {math.hypot(i_d[idx(4390)], i_q[idx(4390)]):.0f} A")
    print("   row by row: " + ", ".join(f"{t[k]:g} s {i_d[k]:.2f} A" for k in range(idx(4400), idx(4480) + 1, 4)))
    for name in ("pm", "stator_winding", "stator_tooth", "stator_yoke", "coolant"):
        print(f"   {name} {d5(cols[name]):+.2f} K", end="")
    print()
    excess = {}
    for name, s in slopes.items():
        excess[name] = dpsi - s * d5(pm)
        print(f"   pm predicts {s * d5(pm) * 1e3:+.3f} mWb at the {name} slope: excess {excess[name] * 1e3:+.3f} mWb"
              f" ({excess[name] / -s:+.1f} K)")

    print("\n2. candidate 1, R_s: (R_s(T_w) - r_s_held)*i_q/w, r_s held at the configured", r_cfg, "Ohm")
    dr = [(r_w[k] - r_cfg) * i_q[k] / w[k] if at_speed[k] else 0.0 for k in range(n)]
    for s in (4390.0, WINDOW[0], 4440.0, WINDOW[1]):
        print(f"   {s:g} s: {m5(dr, s) * 1e3:+.4f} mWb (T_w {m5(tw, s):.1f} C, i_q {m5(i_q, s):.2f} A)")
    print(f"   change over the window {d5(dr) * 1e3:+.4f} mWb")

    print("\n3. candidate 2, an inverter error voltage U along the current vector")
    for s in (4390.0, WINDOW[0], WINDOW[1]):
        k = idx(s)
        print(f"   {s:g} s: q share i_q/|i| {i_q[k] / math.hypot(i_d[k], i_q[k]):.4f}")
    share = m5([q / math.hypot(d, q) for d, q in zip(i_d, i_q)], WINDOW[0])
    need = excess["fitted"] * w0
    print(f"   the excess needs {need:.2f} V on q: U change {need / share:.0f} V at the window's q share")
    pre = idx(4390)
    sh_pre = i_q[pre] / math.hypot(i_d[pre], i_q[pre])
    first = idx(4402.5)
    sh_first = i_q[first] / math.hypot(i_d[first], i_q[first])
    jump = (m5(psi, 4385.0) - slope * m5(pm, 4385.0)) - (psi[first] - slope * pm[first])
    print(f"   the step's own jump of psi_row - s*pm (4380-4390 s to the 4402.5 s row), {-jump * 1e3:+.3f} mWb, as a"
          f" constant U: {jump * w0 / (sh_pre - sh_first):.1f} V (q share {sh_pre:.3f} -> {sh_first:.4f})")
    rd = [(u_d[k] + w[k] * l_q * i_q[k]) / i_d[k] - r_w[k] if at_speed[k] and abs(i_d[k]) > 50 else 0.0
          for k in range(n)]
    mean = lambda x, lo, hi: sum(x[idx(lo):idx(hi) + 1]) / (idx(hi) - idx(lo) + 1)
    e_ru = mean(rd, 145, 155) - mean(rd, 17.5, 22.5)
    print(f"   d row, (u_d + w*L_q*i_q)/i_d - R_s(T_w): 17.5-22.5 s {mean(rd, 17.5, 22.5):+.4f}, 145-155 s"
          f" {mean(rd, 145, 155):+.4f} Ohm: an along-current U moved {abs(e_ru) * 193:.2f} V over the run-up's"
          f" transient (|i_d| 193 A)")

    print("\n4. candidate 3, L_d: the incremental L_d that would make the rise pm's")
    for name, s in slopes.items():
        print(f"   {name}: ({s * d5(pm) * 1e3:.3f} - {terms['u_q/w'] * 1e3:.3f}) mWb / {-d5(i_d):.2f} A ="
              f" {(s * d5(pm) - terms['u_q/w']) / -d5(i_d) * 1e6:.0f} uH (configured {l_d * 1e6:.0f})")
    lo, hi = WINDOW[1], t[-1] - 5
    later = lambda x: (sum(x[idx(hi) - 2:idx(hi) + 3]) - sum(x[idx(lo) - 2:idx(lo) + 3])) / 5
    print(f"   {lo:g} -> {hi:g} s: i_d {later(i_d):+.2f} A, pm {later(pm):+.2f} K, u_q/w"
          f" {later([u / x for u, x in zip(u_q, w)]) * 1e3:+.3f} mWb: incremental L_d"
          f" {(slope * later(pm) - later([u / x for u, x in zip(u_q, w)])) / -later(i_d) * 1e6:.0f} uH"
          " at the fitted slope")

    print("\n5. candidate 4, a transient at each load change: psi_row - s*pm ~ c0 + c1*t + A*exp(-(t-te)/tau)")
    i2 = [(d * d + q * q) / 1e4 for d, q in zip(i_d, i_q)]
    amplitude = {}
    for name, s in slopes.items():
        y = [psi[k] - s * pm[k] if at_speed[k] else 0.0 for k in range(n)]
        for label, te, (lo, hi) in (("run-up", RUNUP_S, RUNUP_FIT), ("step", STEP_S, STEP_FIT)):
            sel = rows(lo, hi)
            best = None
            for j in range(10, 401):
                tau = j * 0.5
                c, r = lstsq([[1.0] * len(sel), [(t[k] - te) / 1e3 for k in sel],
                              [math.exp(-(t[k] - te) / tau) for k in sel]], [y[k] for k in sel])
                sse = sum(v * v for v in r)
                if best is None or sse < best[0]:
                    best = (sse, tau, c)
            sse, tau, c = best
            amplitude[name, label] = c[2]
            print(f"   {name} slope, {label} ({lo:g}-{hi:g} s): A {c[2] * 1e3:+.3f} mWb ({c[2] / -s:+.1f} K) at"
                  f" {te:g} s, tau {tau:.1f} s, rms {math.sqrt(sse / len(sel)) * 1e3:.3f} mWb")

    ru = idx(20.0)
    share_ru = i_q[ru] / math.hypot(i_d[ru], i_q[ru])
    print(f"   the run-up's A as an along-current U (section 3): q share {share_ru:.3f},"
          f" U {amplitude['fitted', 'run-up'] * w[ru] / share_ru:.1f} V")
    d_runup = m5(i2, 20.0) - i2[0]
    d_step = m5(i2, WINDOW[0]) - m5(i2, 4385.0)
    for name in slopes:
        ratio = (amplitude[name, "step"] / d_step) / (amplitude[name, "run-up"] / d_runup)
        print(f"   {name} slope: |i|^2 changes {d_runup:+.2f} / {d_step:+.2f} x 1e4 A^2 (run-up / step): the step's A"
              f" per unit |i|^2 is {ratio:.2f} times the run-up's")
    rate = [(pm[idx(x) + 4] - pm[idx(x) - 4]) / 20.0 for x in (30.0, 50.0, 100.0, 150.0, 200.0)]
    print("   dpm/dt after the run-up at 30, 50, 100, 150, 200 s: " + ", ".join(f"{v:.3f}" for v in rate) + " K/s")

    print("\n6. calibrated on the run-up alone (psi_row - s*pm ~ a + b*t + k*x over"
          f" {RUNUP_FIT[0]:g}-{RUNUP_FIT[1]:g} s), predicting the window's excess")
    cands = [("load offset, lag(|i|^2, tau) [eq. 14.16]", lambda tau: lag(i2, tau)),
             ("lag(i_d, tau)", lambda tau: lag(i_d, tau)),
             ("current-gain drift, i_d*lag(|i|^2, tau)", lambda tau: [d * v for d, v in zip(i_d, lag(i2, tau))]),
             ("pm lead, pm + tau*dpm/dt", None),
             ("stator_winding", None), ("stator_tooth", None), ("stator_yoke", None),
             ("stator_winding - stator_tooth", None), ("stator_winding - pm", None),
             ("copper-loss offset, lag(1.5*R_s(T_w)*|i|^2, tau)",
              lambda tau: lag([1.5 * r * (d * d + q * q) / 1e3 for r, d, q in zip(r_w, i_d, i_q)], tau))]
    for name, s in slopes.items():
        y = [psi[k] - s * pm[k] if at_speed[k] else 0.0 for k in range(n)]
        sel = rows(*RUNUP_FIT)
        print(f"   {name} slope: measured excess {excess[name] * 1e3:+.3f} mWb")
        for label, make in cands:
            if label.startswith("pm lead"):
                taus = [5.0 * j for j in range(0, 25)]
                xs = [lead(pm, tau) for tau in taus]
            elif make is None:
                parts = label.split(" - ")
                xs = [[cols[parts[0]][k] - (cols[parts[1]][k] if len(parts) > 1 else 0.0) for k in range(n)]]
                taus = [None]
            else:
                taus = [5.0 * j for j in range(2, 25)]
                xs = [make(tau) for tau in taus]
            best = None
            for tau, x in zip(taus, xs):
                c, r = lstsq([[1.0] * len(sel), [t[k] / 1e3 for k in sel], [x[k] for k in sel]], [y[k] for k in sel])
                sse = sum(v * v for v in r)
                if best is None or sse < best[0]:
                    best = (sse, tau, c, x)
            sse, tau, c, x = best
            pred = c[2] * d5(x)
            if label.startswith("load offset") and name == "fitted":
                k_delta, tau_delta = c[2] / s, tau
            shown = tau if tau is not None else float("nan")
            print(f"     {label:42s} tau {shown:5.0f} s, run-up rms {math.sqrt(sse / len(sel)) * 1e3:.3f} mWb:"
                  f" predicts {pred * 1e3:+.3f} mWb ({100 * pred / excess[name]:.0f} % of the excess)")

    delta = [k_delta * v for v in lag(i2, tau_delta)]
    print(f"   delta of eq. 14.16 from the run-up (fitted slope): k_delta {k_delta:.2f} K per 1e4 A^2,"
          f" tau {tau_delta:g} s;"
          f" delta {m5(delta, 4390.0):.1f} K at 4390 s, {m5(delta, WINDOW[0]):.1f} K at {WINDOW[0]:g} s,"
          f" {m5(delta, WINDOW[1]):.1f} K at {WINDOW[1]:g} s, {m5(delta, 7490.0):.1f} K at 7490 s")

    print("\n6b. psi_row ~ a + b*pm + c*stator_winding, fitted on each phase alone")
    for label, lo, hi in (("heat-up 20-4390 s", 20.0, 4390.0), ("cool-down 4402.5 s on", 4402.5, t[-1])):
        sel = rows(lo, hi)
        c, _ = lstsq([[1.0] * len(sel), [pm[k] for k in sel], [tw[k] for k in sel]], [psi[k] for k in sel])
        print(f"   {label}: b {c[1] * 1e6:.1f} uWb/K, c {c[2] * 1e6:+.1f} uWb/K")

    print("\n6c. an oracle reading (pm used): the law fitted over the profile (t >= 20 s), the cool-down read back")
    sel = rows(20.0, t[-1])
    cool = rows(4400.1, t[-1])
    for label, extra in (("a + b*pm + e*i_d", None), ("a + b*(pm + delta) + e*i_d", delta)):
        x = [pm[k] + (extra[k] if extra else 0.0) for k in range(n)]
        c, _ = lstsq([[1.0] * len(sel), [x[k] for k in sel], [i_d[k] for k in sel]], [psi[k] for k in sel])
        err = [((psi[k] - c[0] - c[2] * i_d[k]) / c[1] - (extra[k] if extra else 0.0)) - pm[k] for k in cool]
        worst = max(range(len(cool)), key=lambda j: abs(err[j]))
        rms = math.sqrt(sum(v * v for v in err) / len(err))
        print(f"   {label}: e_L {c[2] * 1e6:+.1f} uH, cool-down RMS {rms:.2f} K,"
              f" worst {abs(err[worst]):.2f} K at {t[cool[worst]]:g} s")

    print("\n7. anything else in the window")
    ws = [cols["motor_speed"][k] for k in range(idx(WINDOW[0]), idx(WINDOW[1]) + 1)]
    us = [u_q[k] for k in range(idx(WINDOW[0]), idx(WINDOW[1]) + 1)]
    mu = sum(us) / len(us)
    sd = math.sqrt(sum((v - mu) ** 2 for v in us) / (len(us) - 1))
    print(f"   speed {min(ws):.1f}-{max(ws):.1f} rpm; u_q sd {sd:.3f} V ({sd / w0 * 1e3:.3f} mWb a row,"
          f" {sd / w0 / math.sqrt(5) * 1e3:.3f} mWb a 5-row mean); coolant {d5(cols['coolant']):+.2f} K")

    if a.estimate:
        report_estimate(a.estimate, t, pm, idx)


def report_estimate(path, t, pm, idx):
    with open(path) as f:
        head = f.readline().strip().split(",")
        est = {h: [] for h in head}
        for line in f:
            for h, v in zip(head, line.strip().split(",")):
                est[h].append(float(v) if v not in ("", "nan") else float("nan"))
    if len(est["t"]) != len(t):
        raise SystemExit(f"{path}: {len(est['t'])} rows, the profile has {len(t)}")
    print("\n8. the tools' magnet (rpem estimate --thermal), minus pm")
    r_s = est["r_s"]
    print(f"   r_s {min(r_s):.5f}-{max(r_s):.5f} Ohm, r_s_active on {int(sum(est['r_s_active']))} rows")
    rpem = [x - y for x, y in zip(est["T_magnet_rpem"], pm)]
    fused = [x - y for x, y in zip(est["t_magnet_fused_C"], pm)]
    mean = lambda x, lo, hi: sum(x[idx(lo):idx(hi) + 1]) / (idx(hi) - idx(lo) + 1)
    print(f"   RPEM alone: {mean(rpem, 4380, 4390):+.2f} K over 4380-4390 s, {rpem[idx(4400)]:+.2f} K at 4400 s,"
          f" {mean(rpem, 4475, 4485):+.2f} K over 4475-4485 s")
    cool = [k for k in range(len(t)) if t[k] > 4400]
    worst = max(cool, key=lambda k: abs(fused[k]))
    print(f"   fused worst {fused[worst]:+.2f} K at {t[worst]:g} s: RPEM alone {rpem[worst]:+.2f} K there; fused"
          f" {est['t_magnet_fused_C'][worst]:.2f}, RPEM alone {est['T_magnet_rpem'][worst]:.2f}, pm {pm[worst]:.2f} C;"
          f" sd {est['t_magnet_fused_sd_C'][worst - 1]:.2f} -> {est['t_magnet_fused_sd_C'][worst]:.2f} K")
    f = est["t_magnet_fused_C"]
    dips = [k for k in cool if t[k] < 4600 and f[k] < min(f[k - 1], f[k + 1]) - 1.0]
    print("   one-row dips of the fused magnet (> 1 K below both neighbours) to 4600 s: "
          + ", ".join(f"{t[k]:g} s ({fused[k]:+.1f} K, RPEM alone {rpem[k]:+.1f} K)" for k in dips))


if __name__ == "__main__":
    main()
