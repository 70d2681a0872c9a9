#!/usr/bin/env python3
"""check_vesc_rpemd.py's --prompt-replies judgement on inputs whose answer is known, without a VM: the emulator's
stall list as the emulator prints it (the stall lines are from a real run of tests/vm/vesc_rpemd.sh, c9ce704's
fresh-clone CI; the histogram and counter lines are written here in the emulator's and rpemd's formats) parsed to the digit, negative arrivals included (polls the kernel stamped before the emulator's t = 0); a stale
estimate excused from a stalled poll's arrival to two publishing periods after its reply, and only there; the
silence excused as before; timeouts allowed for the stalled replies.

  test_check_vesc_rpemd.py

Each check prints ok/FAIL; exit 1 on a failure. Only the standard library."""
import os
import sys

sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_vesc_rpemd as check  # noqa: E402

failures = 0


def expect(what, ok, detail=""):
    global failures
    print(("ok   " if ok else "FAIL ") + what + ("" if ok else ": %s" % detail))
    failures += 0 if ok else 1


HISTOGRAM = ("rpem sim: VESC 17 replies sent after their poll's arrival: <=1 ms 640, <=2 ms 10, <=5 ms 4, <=10 ms 2, "
             "<=20 ms 1, <=100 ms 0, <=1000 ms 2, later 0; the latest 0.567 s\n")
STOPPED = "rpem sim: VESC 17 stopped at 70.000 s drive time (0.001 s behind the host): 710 polls, 30 unheard while silent\n"


def emulator(stall_line):
    return STOPPED + HISTOGRAM + stall_line + "\n"


def diagnostics(timeouts):
    return "vesc_polls 710 vesc_stolen 0 vesc_replies 670 vesc_timeouts %d vesc_late_replies 0\n" % timeouts


def judge(stall_line, stale_at, timeouts=40, publish_s=0.1):
    est = [{'te': t, 'state': 2} for t in stale_at] + [{'te': 10.0, 'state': 0}]
    report, errors = [], []
    check.check_prompt_replies(emulator(stall_line), diagnostics(timeouts), est, 0.1, publish_s, report, errors)
    return report, errors


def main():
    # Parsed as printed: the count, then (arrival, delay) pairs; an arrival before t = 0 keeps its sign.
    line = ("rpem sim: VESC 17 stalled 100 ms or more 3 times (arrival s:delay s, the first 64): -0.086:0.123 "
            "-0.064:0.103 -0.061:0.100")
    count, stalls = check.emulator_stalls(line)
    expect("three stalls counted", count == 3, count)
    expect("their arrivals and delays, signs kept", stalls == [(-0.086, 0.123), (-0.064, 0.103), (-0.061, 0.1)], stalls)
    none = "rpem sim: VESC 17 stalled 100 ms or more 0 times (arrival s:delay s, the first 64):"
    expect("no stall: an empty list", check.emulator_stalls(none) == (0, []), check.emulator_stalls(none))
    many = ("rpem sim: VESC 17 stalled 100 ms or more 146 times (arrival s:delay s, the first 64): 30.912:0.116 "
            "30.913:0.118")
    expect("more stalls than listed: the count is the emulator's", check.emulator_stalls(many)[0] == 146)

    # A stall of 0.567 s on the poll that reached the emulator at 34.100 s: excused from 34.100 s to
    # 34.100 + 0.567 + 2 × 0.1 = 34.867 s, not after.
    stall = "rpem sim: VESC 17 stalled 100 ms or more 1 times (arrival s:delay s, the first 64): 34.100:0.567"
    report, errors = judge(stall, [34.2, 34.7, 34.86])
    expect("stale estimates inside the stall's window pass", not errors, errors)
    expect("the report says how many were excused", '3 estimates stale while the emulator stalled' in report, report)
    report, errors = judge(stall, [34.7, 34.9])
    expect("a stale estimate after the window fails", len(errors) == 1 and 'first at 34.9 s' in errors[0], errors)
    report, errors = judge(stall, [34.05])
    expect("a stale estimate before the poll arrived fails", len(errors) == 1, errors)
    report, errors = judge(none, [34.7])
    expect("without a stall a stale estimate fails, as before", len(errors) == 1, errors)
    report, errors = judge(none, [45.5, 48.9])
    expect("the silence 45-49 s is excused, as before", not errors, errors)
    # Timeouts: the silence's 30, a second at each end (2 × ⌈710/70⌉ = 22), and the replies the emulator's histogram
    # puts at or after the 0.1 s timeout (its <=1000 ms bin: 2).
    report, errors = judge(stall, [], timeouts=54)
    expect("timeouts within the silence, the ends and the stalled replies pass", not errors, errors)
    report, errors = judge(stall, [], timeouts=55)
    expect("one timeout more fails", len(errors) == 1 and '55 timeouts' in errors[0], errors)
    print("test_check_vesc_rpemd: %s" % ("passed" if failures == 0 else "%d FAILED" % failures))
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
