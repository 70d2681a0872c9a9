#!/usr/bin/env python3
"""Checks the outputs of tests/vm/daemon_suite.sh (rpemd end to end over vcan0 and LCM).

    check_daemon_suite.py OUT_DIR

1. -8 % steps of R_s (2 s, standstill) and psi_m (16 s, 0.3 pu): the LCM estimates enter and stay within
   ±1 % of the simulated truth within twice the paper's times (tab_comparison: R_s 8 s, psi_m ~2 s) —
   without loss, with 10 % random frame loss, and with 10 % loss in bursts of 12 frames (gaps counted).
2. Faults: vcan0 down → stale, up → running again without a restart (reopen counted); a blocked LCM
   route → publish failures counted and the loop's overrun rate unchanged; malformed frames and
   commands counted and ignored, keyed commands acknowledged; an attacker without the keys (unsigned and
   guessed-key commands with larger sequence numbers, a captured command replayed and bit-flipped,
   forged estimates) gets nothing applied, each attack counted by its reason, rpemd's estimates kept,
   the forged ones flagged FORGED by `rpem listen --key`; SIGKILL and restart resume from the state
   file, and the captured command is still a replay after the restart.
3. Storm: SIGHUP, commands and vcan0 down/up at once — commands applied once and in order, reloads
   applied or refused with a counted reason, the socket reopened, the state file whole.
"""
import csv
import json
import re
import sys

failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def estimates(path):
    rows = list(csv.DictReader(open(path)))
    return [{k: (v if k == "auth" else float(v)) for k, v in r.items()} for r in rows]


def truth(path):
    t, psi, rs = [], [], []
    for r in csv.DictReader(open(path)):
        t.append(float(r["t"]))
        psi.append(float(r["psi_m"]))
        rs.append(float(r["r_s"]))
    return t, psi, rs


def diagnostics(path):
    out = []
    for line in open(path):
        m = re.match(r"diag (\d+): (.*)", line)
        if not m:
            continue
        d = {"utime": int(m.group(1))}
        for key, value in re.findall(r"([a-z][a-z ]*?) (-?\d+)(?=[ |]|$)", m.group(2)):
            d[key.strip()] = int(value)
        last = re.search(r"last (\d+):(\d+)", m.group(2))
        if last:
            d["last seq"], d["last result"] = int(last.group(1)), int(last.group(2))
        out.append(d)
    return out


def convergence(est, tr, key, step_s, end_s):
    """Seconds from the step until the estimate is within ±1 % of the truth and stays there until end_s."""
    t_truth, psi, rs = tr
    series = psi if key == "psi_m" else rs
    period = t_truth[1] - t_truth[0]
    settled = None
    for e in est:
        t = e["sample_time_us"] * 1e-6
        if t < step_s or t > end_s:
            continue
        k = min(len(series) - 1, round(t / period))
        inside = abs(e[key] - series[k]) <= 0.01 * series[k]
        if inside and settled is None:
            settled = t
        elif not inside:
            settled = None
    return None if settled is None else settled - step_s


def steps(out, name):
    est = estimates(f"{out}/{name}_est.csv")
    tr = truth(f"{out}/{name}_truth.csv")
    rs = convergence(est, tr, "r_s", 2.0, 12.0)
    psi = convergence(est, tr, "psi_m", 16.0, 26.0)
    check(rs is not None and rs <= 16.0, f"{name}: r_s within ±1 % {rs} s after its step (paper 8 s; limit 16 s)")
    check(psi is not None and psi <= 4.0, f"{name}: psi_m within ±1 % {psi} s after its step (paper ~2 s; limit 4 s)")
    diag = diagnostics(f"{out}/{name}_listen.txt")
    return diag[-1] if diag else {}


def overrun_rate(diag):
    """Overruns per second between the first and the last of these diagnostics."""
    if len(diag) < 2:
        return float("nan")
    return (diag[-1]["overruns"] - diag[0]["overruns"]) / max(1e-6, (diag[-1]["utime"] - diag[0]["utime"]) * 1e-6)


def storm(out):
    """SIGHUP, commands and vcan0 down/up at once (daemon_suite.sh, "storm")."""
    events = {}
    for line in open(f"{out}/storm_events.txt"):
        stamp, what = line.split(" ", 1)
        events[what.strip()] = int(stamp) * 1_000_000
    start, end = events["storm start"], events["storm end"]
    diag = diagnostics(f"{out}/storm_listen.txt")
    est = estimates(f"{out}/storm_est.csv")
    last = diag[-1] if diag else {}
    applied, received = last.get("applied", -1), last.get("commands", -2)
    malformed, rejected = last.get("malformed", 0), last.get("rejected", 0)
    check(applied == received - malformed - rejected,
          f"storm: every accepted command applied once (received {received} = malformed {malformed} + rejected {rejected} + applied {applied})")
    check(received >= 900, f"storm: {received} of the 1002 commands arrived")
    check(last.get("sequence errors", -1) == 0, "storm: no command applied out of sequence order")
    check(last.get("last seq") == 2001 and last.get("last result") == 1, "storm: the last command (seq 2001) acknowledged")
    requests = last.get("reload requests", -1)
    reasons = [last.get(k, 0) for k in ("reloads", "invalid", "restart required", "busy")]
    check(requests == sum(reasons) and requests >= 1,
          f"storm: every reload applied or refused with a reason ({requests} = applied {reasons[0]} + invalid {reasons[1]} "
          f"+ restart required {reasons[2]} + busy {reasons[3]})")
    check(reasons[0] >= 1 and reasons[1] >= 1 and reasons[2] >= 1, "storm: reloads applied, refused as invalid and as needing a restart")
    during = [x for x in diag if start <= x["utime"] <= end + 1_000_000]
    check(bool(during) and during[-1].get("reopens", 0) >= 3, f"storm: vcan0's outages reopened the socket ({during[-1].get('reopens') if during else '?'} reopens)")
    check(any(start <= e["utime"] <= end and e["state"] == 2 for e in est), "storm: stale while vcan0 was down")
    final = est[-1] if est else {}
    check(final.get("frozen") == 1 and abs(final.get("psi_m", 0) - 1.123) < 1e-5 and abs(final.get("r_s", 0) - 2.345) < 1e-5,
          f"storm: the last SET_VALUES arrived whole and the loop froze ({final.get('psi_m')}, {final.get('r_s')})")
    try:
        state = json.load(open(f"{out}/storm_state.json"))
        check(state.get("format") == "rpemd-estimates-1", "storm: the state file is whole")
    except (OSError, ValueError) as e:
        check(False, f"storm: the state file is whole ({e})")
    quiet = [x for x in diag if x["utime"] < start and x["state"] == 1]
    print(f"storm: loop overruns {overrun_rate(during):.1f}/s during the storm, {overrun_rate(quiet):.1f}/s in the quiet "
          f"seconds before (emulated VM; a figure, not a check)")


def main(out):
    d = steps(out, "steps")
    check(d.get("lost", -1) == 0 and d.get("gaps", -1) == 1, "steps: no frame lost, one gap (the stream's start)")
    for name in ("loss_random", "loss_burst"):
        d = steps(out, name)
        check(d.get("lost", 0) > 0 and d.get("gaps", 0) > 1, f"{name}: frames lost {d.get('lost')} and gaps {d.get('gaps')} counted")

    events = {}
    for line in open(f"{out}/faults_events.txt"):
        stamp, what = line.split(" ", 1)
        events[what.strip()] = int(stamp) * 1_000_000
    est = estimates(f"{out}/faults_est.csv")
    diag = diagnostics(f"{out}/faults_listen.txt")

    down, up = events["vcan0 down"], events["vcan0 up"]
    check(any(down <= e["utime"] <= up + 2_000_000 and e["state"] == 2 for e in est), "faults: stale while vcan0 is down")
    check(any(up + 1_000_000 <= e["utime"] < events["lcm blocked"] and e["state"] == 1 for e in est),
          "faults: running again after vcan0 came back, without a restart")
    after_up = [x for x in diag if up < x["utime"] < events["sigkill"]]
    check(bool(after_up) and after_up[-1].get("reopens", 0) >= 1, "faults: the socket reopen is counted")

    blocked, restored = events["lcm blocked"], events["lcm restored"]
    before = [x for x in diag if x["utime"] < blocked and x["state"] == 1]
    after = [x for x in diag if restored < x["utime"] < events["sigkill"]]
    check(bool(after) and after[0].get("publish failures", 0) > 0, "faults: publish failures counted while LCM was blocked")
    if len(before) >= 2 and after:
        rate_before = (before[-1]["overruns"] - before[0]["overruns"]) / max(1e-6, (before[-1]["utime"] - before[0]["utime"]) * 1e-6)
        rate_block = (after[0]["overruns"] - before[-1]["overruns"]) / max(1e-6, (after[0]["utime"] - before[-1]["utime"]) * 1e-6)
        check(rate_block <= 2.0 * rate_before + 5.0,
              f"faults: loop overruns {rate_block:.1f}/s while LCM was blocked, {rate_before:.1f}/s before (emulated VM)")
    final = [x for x in diag if events["malformed"] < x["utime"] < events["attacker"]]
    last = final[-1] if final else {}
    check(last.get("crc", 0) >= 1 and last.get("dlc", 0) >= 2, f"faults: malformed frames counted (crc {last.get('crc')}, dlc {last.get('dlc')})")
    check(last.get("malformed", 0) >= 1, "faults: the malformed command counted")
    check(last.get("rejected", 0) >= 1, "faults: the command with an old sequence number rejected")
    check(last.get("last seq") == 6 and last.get("last result") == 1, "faults: the last command (seq 6) acknowledged as applied")
    check(any(e["frozen"] == 1 for e in est if e["utime"] >= events["malformed"]), "faults: freeze applied")

    # The attacker (issue 13): nothing applied, each attack counted by its reason, rpemd's estimates
    # kept (and verified), the forged ones flagged by `rpem listen --key`.
    attack = [x for x in diag if events["attacker end"] < x["utime"] < events["sigkill"]]
    a = attack[-1] if attack else {}
    check(a.get("applied", -1) == last.get("applied", -2), f"attacker: no command applied ({last.get('applied')} before, {a.get('applied')} after)")
    check(a.get("unauthenticated", 0) - last.get("unauthenticated", 0) == 1, "attacker: the unsigned command counted as unauthenticated")
    check(a.get("bad mac", 0) - last.get("bad mac", 0) == 3, f"attacker: the guessed-key commands and the flipped bit counted as bad MAC ({a.get('bad mac')})")
    check(a.get("replayed", 0) - last.get("replayed", 0) == 1, "attacker: the captured command's replay counted as replayed")
    ours = [e for e in est if e["utime"] >= events["attacker"] and e.get("auth") == "verified"]
    forged = [e for e in est if e.get("auth") == "FORGED"]
    check(len(forged) == 3 and all(abs(e["psi_m"] - 0.6) < 1e-9 for e in forged), f"attacker: rpem listen flagged the 3 forged estimates as FORGED ({len(forged)})")
    check(bool(ours) and all(abs(e["psi_m"] - 0.6) > 0.1 and e["frozen"] == 0 for e in ours),
          "attacker: rpemd's own (verified) estimates kept their values and stayed unfrozen")
    check(all(e.get("auth") in ("verified", "FORGED") for e in est), "attacker: every other estimate verified under the publish key")

    restart_log = open(f"{out}/restarted_rpemd.txt").read()
    check("resuming from estimates" in restart_log, "restart: rpemd resumed from its state file after SIGKILL")
    first = re.search(r"rpemd \w+ +n=\S+ pu +psi_m=([0-9.]+) Wb", restart_log)
    # The persisted value is whatever the killed rpemd last wrote (the suite copies the file right after
    # SIGKILL); the status line prints 4 decimals.
    try:
        persisted = json.load(open(f"{out}/killed_state.json")).get("psi_m_Wb")
    except (OSError, ValueError):
        persisted = None
    check(first is not None and persisted is not None and abs(float(first.group(1)) - persisted) <= 6e-5
          and abs(persisted - 1.14) > 1e-3,
          f"restart: its first estimate ({first.group(1) if first else '?'} Wb) is the persisted one ({persisted}), "
          "not the configured 1.14 Wb")
    after_restart = [x for x in diag if x["utime"] > events["sigkill"]]
    check(bool(after_restart) and after_restart[-1].get("state file") == 1, "restart: diagnostics report the state file loaded")
    check(bool(after_restart) and after_restart[-1].get("replayed") == 1 and after_restart[-1].get("applied") == 0,
          "restart: the captured command is still a replay after the restart (sequence number persisted)")

    storm(out)
    print("check_daemon_suite: " + ("passed" if not failures else f"{len(failures)} failed"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
