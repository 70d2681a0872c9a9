#!/usr/bin/env python3
"""scripts/paderborn_to_drive_log.py on the data set as it is published: one file of many profiles (a profile_id
column, 2 Hz rows), beside the carried every-5th excerpt of one profile. Built from the carried rows: the first
1000 labelled profile 4, the rest profile 6, as the published file holds its 69 profiles one after another.

  test_paderborn_to_drive_log.py SOURCE_DIR

Each check prints ok/FAIL; exit 1 on a failure. Only the standard library."""
import csv
import math
import os
import subprocess
import sys
import tempfile

failures = 0


def check(what: str, ok: bool, detail: str = "") -> None:
    global failures
    print(("ok   " if ok else "FAIL ") + what + ("" if ok else f": {detail}"))
    failures += 0 if ok else 1


def main() -> int:
    root = sys.argv[1]
    script = os.path.join(root, "scripts/paderborn_to_drive_log.py")
    excerpt = os.path.join(root, "data/paderborn-motor-temperature/profile_A_every5th.csv")
    with open(excerpt, newline="") as f:
        rows = list(csv.DictReader(f))
    fields = list(rows[0].keys())
    work = tempfile.mkdtemp(prefix="paderborn_conv_")

    def write(name: str, ids) -> str:
        path = os.path.join(work, name)
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(fields + ["profile_id"])
            for r, pid in zip(rows, ids):
                w.writerow([r[c] for c in fields] + [pid])
        return path

    def convert(source: str, *options: str):
        out = os.path.join(work, "out.csv")
        if os.path.exists(out):
            os.remove(out)
        p = subprocess.run([sys.executable, script, source, out, "--pole-pairs", "4", *options], capture_output=True,
                           text=True)
        table = []
        if p.returncode == 0:
            with open(out, newline="") as f:
                table = list(csv.DictReader(f))
        return p.returncode, p.stderr, table

    published = write("published.csv", ["4"] * 1000 + ["6"] * (len(rows) - 1000))
    interleaved = write("interleaved.csv", ["4"] * 500 + ["6"] * 500 + ["4"] * (len(rows) - 1000))

    code, err, _ = convert(excerpt)
    check("no --sample-period-s: refused (no default that would scale every time constant)",
          code == 2 and "--sample-period-s" in err, f"exit {code}: {err}")
    code, err, _ = convert(excerpt, "--sample-period-s", "0")
    check("--sample-period-s 0: refused, exit 64", code == 64 and "positive" in err, f"exit {code}: {err}")

    code, err, t = convert(excerpt, "--sample-period-s", "2.5")
    check("the excerpt (one profile, no profile_id): every row, 2.5 s apart", code == 0 and len(t) == len(rows) and
          float(t[-1]["t"]) == 2.5 * (len(rows) - 1), f"exit {code}, {len(t)} rows: {err}")
    code, err, _ = convert(excerpt, "--sample-period-s", "2.5", "--profile", "4")
    check("--profile on a file without profile_id: refused, exit 64", code == 64 and "no profile_id" in err,
          f"exit {code}: {err}")

    code, err, _ = convert(published, "--sample-period-s", "0.5")
    check("several profiles without --profile: refused, exit 64, the ids named",
          code == 64 and "profile_id 4, 6" in err and "--profile" in err, f"exit {code}: {err}")

    code, err, t = convert(published, "--sample-period-s", "0.5", "--profile", "6")
    n = len(rows) - 1000
    ok = code == 0 and len(t) == n
    if ok:  # each row is the source's, t from 0 at 2 Hz, ω_el = rpm·2π/60·p
        for k in (0, 1, n // 2, n - 1):
            src, got = rows[1000 + k], t[k]
            ok = ok and float(got["t"]) == 0.5 * k and float(got["u_d"]) == float(src["u_d"])
            ok = ok and math.isclose(float(got["omega_el"]), float(src["motor_speed"]) * 2 * math.pi / 60 * 4, rel_tol=1e-15)
            ok = ok and float(got["T_magnet"]) == float(src["pm"])
    check(f"--profile 6: its {n} rows, t = 0.5·k from its first, each the source row's", ok, f"exit {code}: {err}")
    code6 = (code, [r["u_q"] for r in t])
    code, err, t = convert(published, "--sample-period-s", "0.5", "--profile", "6.0")
    check("--profile 6.0 is profile 6 (ids compared as numbers)", (code, [r["u_q"] for r in t]) == code6,
          f"exit {code}: {err}")
    code, err, _ = convert(published, "--sample-period-s", "0.5", "--profile", "5")
    check("an id the file does not hold: exit 65, the ids named", code == 65 and "holds 4, 6" in err, f"exit {code}: {err}")
    code, err, _ = convert(interleaved, "--sample-period-s", "0.5", "--profile", "4")
    check("a profile in two runs: exit 65, both runs' lines named",
          code == 65 and "not contiguous" in err and "lines 2–501" in err and "lines 1002–" in err, f"exit {code}: {err}")

    short = os.path.join(work, "short.csv")
    with open(published) as f, open(short, "w") as g:
        lines = f.readlines()
        lines[1500] = ",".join(lines[1500].split(",")[:5]) + "\n"
        g.writelines(lines)
    code, err, _ = convert(short, "--sample-period-s", "0.5", "--profile", "6")
    check("a short row: exit 65 naming its line", code == 65 and ":1501: the row has 5 cells, the header 13" in err,
          f"exit {code}: {err}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
