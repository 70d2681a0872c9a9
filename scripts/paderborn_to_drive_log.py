#!/usr/bin/env python3
"""Converts the Paderborn "Electric Motor Temperature" bench data (data/paderborn-motor-temperature/,
W. Kirchgässner, O. Wallscheid, J. Böcker, LEA Paderborn University, CC BY-SA 4.0) into a rotor-frame drive
log (docs/drive-log.md) for `rpem diagnose`, `rpem estimate` and `rpem thermal fit`. The source files are
read, never changed.

  paderborn_to_drive_log.py SOURCE.csv OUT.csv --pole-pairs P --sample-period-s S [--profile ID] [--averaged]
                            [--coolant] [--no-magnet] [--winding-until-s S]

The data set does not publish the pole-pair number; its dq equations fix only p·L and p·ψm, so the
electrical speed needs an assumed p (docs/diagnose.md states the one used). Nor do its files have a time
column: rows are 2 Hz samples as published (--sample-period-s 0.5), and profile_A_every5th.csv keeps every
5th (--sample-period-s 2.5). There is no default: a wrong one would scale every time constant silently.
Columns written: t, omega_el (from motor_speed [rpm]), u_d, u_q, i_d, i_q, T_winding (stator_winding),
T_magnet (pm); theta_el and u_dc are not in the data (a rotor-frame-only log may omit them).

  --profile ID       the rows of one measurement profile (the published file's profile_id column holds 69,
                     one after another; each is its own session, from its own start): required where the
                     file holds more than one, and its rows must be contiguous. t starts at 0 on its first row
  --averaged         an averaged log instead (docs/drive-log.md, "Averaged log"): a t_start column equal to t
                     marks each row as an instantaneous steady-state sample
  --coolant          also T_coolant (the data set's coolant column)
  --no-magnet        leave T_magnet out: the magnet sensor hidden from every tool (docs/thermal.md)
  --winding-until-s  T_winding only up to this time, `nan` (not reported) after it; needs --averaged

Errors name the file and line and exit 65 (the data's fault) or 64 (the command's).
"""
import argparse
import csv
import math
import sys


def profile_key(cell: str):
    """A profile_id as a number where it is one (the published file writes integers; '4' and '4.0' are one profile)."""
    try:
        return float(cell)
    except ValueError:
        return cell.strip()


def select_profile(source: str, wanted):
    """The lines (first, last) to convert: every row of a file of one profile, or --profile's contiguous run of a
    file of several; one pass over the profile_id column. Returns an exit code instead where the choice is
    missing or impossible (the error printed)."""
    with open(source, newline="") as f:
        rows = csv.reader(f)
        header = next(rows, [])
        column = header.index("profile_id") if "profile_id" in header else None
        if wanted is not None and column is None:
            print(f"{source}:1: --profile {wanted}: the file has no profile_id column (it holds one profile: leave "
                  f"--profile out)", file=sys.stderr)
            return 64
        runs = []  # [profile key, its cell as written, first line, last line]
        for line, r in enumerate(rows, start=2):
            if len(r) != len(header):
                print(f"{source}:{line}: the row has {len(r)} cells, the header {len(header)}", file=sys.stderr)
                return 65
            cell = r[column] if column is not None else ""
            key = profile_key(cell)
            if not runs or runs[-1][0] != key:
                runs.append([key, cell, line, line])
            runs[-1][3] = line
    if not runs:
        print(f"{source}: no data rows", file=sys.stderr)
        return 65
    ids = []
    for _, cell, _, _ in runs:
        if cell not in ids:
            ids.append(cell)
    if wanted is None:
        if len(ids) > 1:
            print(f"{source}: holds {len(ids)} profiles (profile_id {', '.join(ids)}), each its own session from "
                  f"its own start: choose one with --profile", file=sys.stderr)
            return 64
        return runs[0][2], runs[-1][3]
    own = [(first, last) for key, _, first, last in runs if key == profile_key(wanted)]
    if not own:
        print(f"{source}: no row of profile_id {wanted} (the file holds {', '.join(ids)})", file=sys.stderr)
        return 65
    if len(own) > 1:
        spans = ", ".join(f"lines {first}–{last}" for first, last in own)
        print(f"{source}: profile_id {wanted}'s rows are not contiguous ({spans}): the time between the runs is "
              f"not in the file", file=sys.stderr)
        return 65
    return own[0]

def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source")
    ap.add_argument("out")
    ap.add_argument("--pole-pairs", type=int, required=True, help="assumed pole-pair number")
    ap.add_argument("--sample-period-s", type=float, required=True,
                    help="time between rows: 0.5 for the data set as published (2 Hz), 2.5 for profile_A_every5th.csv")
    ap.add_argument("--profile", help="the profile_id whose rows to convert (where the file holds several)")
    ap.add_argument("--averaged", action="store_true", help="write an averaged log (t_start = t)")
    ap.add_argument("--coolant", action="store_true", help="also write T_coolant")
    ap.add_argument("--no-magnet", action="store_true", help="leave the magnet temperature (pm) out")
    ap.add_argument("--winding-until-s", type=float, default=None, help="T_winding only up to this time")
    a = ap.parse_args()
    if a.winding_until_s is not None and not a.averaged:
        print("--winding-until-s needs --averaged (a drive log has no 'not reported' cell)", file=sys.stderr)
        return 64
    if not (math.isfinite(a.sample_period_s) and a.sample_period_s > 0.0):
        print(f"--sample-period-s {a.sample_period_s}: the time between rows must be a positive number of seconds",
              file=sys.stderr)
        return 64
    need = ["u_d", "u_q", "i_d", "i_q", "motor_speed", "stator_winding"]
    if not a.no_magnet:
        need.append("pm")
    if a.coolant:
        need.append("coolant")
    with open(a.source, newline="") as src:
        fields = csv.DictReader(src).fieldnames or []
    missing = [c for c in need if c not in fields]
    if missing:
        print(f"{a.source}:1: missing columns {', '.join(missing)}", file=sys.stderr)
        return 65
    lines = select_profile(a.source, a.profile)
    if isinstance(lines, int):
        return lines
    first, last = lines
    with open(a.source, newline="") as src, open(a.out, "w", newline="") as dst:
        rows = csv.DictReader(src)
        out = csv.writer(dst)
        header = ["t"] + (["t_start"] if a.averaged else []) + ["omega_el", "u_d", "u_q", "i_d", "i_q", "T_winding"]
        header += [] if a.no_magnet else ["T_magnet"]
        header += ["T_coolant"] if a.coolant else []
        out.writerow(header)
        selected = ((line, r) for line, r in enumerate(rows, start=2) if first <= line <= last)
        for k, (line, r) in enumerate(selected):
            try:
                v = {c: float(r[c]) for c in need}
            except ValueError as e:
                print(f"{a.source}:{line}: {e}", file=sys.stderr)
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
