#!/usr/bin/env python3
"""Converts the Paderborn "Electric Motor Temperature" bench data (data/paderborn-motor-temperature/,
W. Kirchgässner, O. Wallscheid, J. Böcker, LEA Paderborn University, CC BY-SA 4.0) into a rotor-frame drive
log (docs/drive-log.md) for `rpem diagnose`, `rpem estimate` and `rpem thermal fit`. The source files are
read, never changed.

  paderborn_to_drive_log.py SOURCE.csv OUT.csv --pole-pairs P [--sample-period-s 2.5] [--averaged]
                            [--coolant] [--no-magnet] [--winding-until-s S]

The data set does not publish the pole-pair number; its dq equations fix only p·L and p·ψm, so the
electrical speed needs an assumed p (docs/diagnose.md states the one used). Rows are 2 Hz samples, every
5th kept in profile_A_every5th.csv: one row per 2.5 s. Columns written: t, omega_el (from motor_speed
[rpm]), u_d, u_q, i_d, i_q, T_winding (stator_winding), T_magnet (pm); theta_el and u_dc are not in the
data (a rotor-frame-only log may omit them).

  --averaged         an averaged log instead (docs/drive-log.md, "Averaged log"): a t_start column equal to t
                     marks each row as an instantaneous steady-state sample
  --coolant          also T_coolant (the data set's coolant column)
  --no-magnet        leave T_magnet out: the magnet sensor hidden from every tool (docs/thermal.md)
  --winding-until-s  T_winding only up to this time, `nan` (not reported) after it; needs --averaged
"""
import argparse
import csv
import math
import sys


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source")
    ap.add_argument("out")
    ap.add_argument("--pole-pairs", type=int, required=True, help="assumed pole-pair number")
    ap.add_argument("--sample-period-s", type=float, default=2.5, help="time between rows (default 2.5)")
    ap.add_argument("--averaged", action="store_true", help="write an averaged log (t_start = t)")
    ap.add_argument("--coolant", action="store_true", help="also write T_coolant")
    ap.add_argument("--no-magnet", action="store_true", help="leave the magnet temperature (pm) out")
    ap.add_argument("--winding-until-s", type=float, default=None, help="T_winding only up to this time")
    a = ap.parse_args()
    if a.winding_until_s is not None and not a.averaged:
        print("--winding-until-s needs --averaged (a drive log has no 'not reported' cell)", file=sys.stderr)
        return 64
    need = ["u_d", "u_q", "i_d", "i_q", "motor_speed", "stator_winding"]
    if not a.no_magnet:
        need.append("pm")
    if a.coolant:
        need.append("coolant")
    with open(a.source, newline="") as src, open(a.out, "w", newline="") as dst:
        rows = csv.DictReader(src)
        missing = [c for c in need if c not in (rows.fieldnames or [])]
        if missing:
            print(f"{a.source}:1: missing columns {', '.join(missing)}", file=sys.stderr)
            return 65
        out = csv.writer(dst)
        header = ["t"] + (["t_start"] if a.averaged else []) + ["omega_el", "u_d", "u_q", "i_d", "i_q", "T_winding"]
        header += [] if a.no_magnet else ["T_magnet"]
        header += ["T_coolant"] if a.coolant else []
        out.writerow(header)
        for k, r in enumerate(rows):
            try:
                v = {c: float(r[c]) for c in need}
            except ValueError as e:
                print(f"{a.source}:{k + 2}: {e}", file=sys.stderr)
                return 65
            t = k * a.sample_period_s
            omega = v["motor_speed"] * 2.0 * math.pi / 60.0 * a.pole_pairs
            winding = repr(v["stator_winding"])
            if a.winding_until_s is not None and t > a.winding_until_s:
                winding = "nan"
            row = [repr(t)] + ([repr(t)] if a.averaged else [])
            row += [repr(omega), repr(v["u_d"]), repr(v["u_q"]), repr(v["i_d"]), repr(v["i_q"]), winding]
            row += [] if a.no_magnet else [repr(v["pm"])]
            row += [repr(v["coolant"])] if a.coolant else []
            out.writerow(row)
    return 0


if __name__ == "__main__":
    sys.exit(main())
