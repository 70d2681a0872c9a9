#!/usr/bin/env python3
"""Checks rpemd (source: vesc) against the emulated VESC (tests/vm/vesc_rpemd.sh), run NAME in DIR:

- it starts off the truth (the datasheet configuration; the plant is +6 % ψm, -8 % R_s) and converges:
  ψm within 1 % of the plant's at the end of the speed phases 20-32 s and 40-52 s (the latter after the
  emulator's silence), R_s within 3 % at the end of the standstill phase 32-40 s (where the scheduler lets
  R_s adapt);
- it publishes magnet and winding temperatures (finite; not compared with the plant's: they follow from the
  configuration's reference values, which are off the plant's on purpose);
- it survives the silence 45-48 s: estimates keep coming and its sample count grows again after it;
- it counts the second poller (cangen from 55 s to 60 s) stealing its averages;
- with --prompt-replies (a poll slow enough that every reply comes well within its period: 10 Hz, run with the
  stale timeout rpemd chooses for it), no estimate is stale but in the silence and after the emulator stops; it
  times out only the polls nobody answered — those of the emulator's silence, which the emulator counts, and those
  sent before it listens and after it stops (a second at each end: tests/vm/vesc_rpemd.sh) — and takes no reply
  as late (at most 1 % of them, for a VM that stalls a whole period). A reply the emulator itself sent later than
  rpemd's reply timeout after the poll reached it (its histogram of reply delays; a VM under TCG on a busy host
  stalls for 100 ms and more) cannot have come in time: its timeout, and its late arrival, are the VM's, and each is
  allowed once more. A chain of timeouts behind one lost reply (the poller's fault this check exists for) would
  still exceed that by hundreds. Likewise an estimate goes stale while the emulator itself sits on a reply (it lists
  each reply it sent 100 ms or more after its poll): such an estimate is excused from the poll's arrival until two
  of rpemd's publishing periods after the reply went out.

  check_vesc_rpemd.py DIR NAME [--prompt-replies]
"""
import bisect
import csv
import math
import re
import sys


def main():
    d, name = sys.argv[1], sys.argv[2]
    emu = open('%s/%s_emulator.txt' % (d, name)).read()
    t0 = float(re.search(r't = 0 at CLOCK_REALTIME ([0-9.]+) s', emu).group(1))
    truth = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(open('%s/%s_truth.csv' % (d, name)))]
    tt = [r['t'] for r in truth]
    # rpem listen's CSV: numeric columns, and `auth` (verified / unverified / FORGED), which is text.
    est = [{k: (v if k == 'auth' else float(v)) for k, v in r.items()}
           for r in csv.DictReader(open('%s/%s_est.csv' % (d, name)))]
    for e in est:
        e['te'] = e['utime'] * 1e-6 - t0
    errors = []

    def truth_at(t):
        return truth[min(bisect.bisect_left(tt, t), len(truth) - 1)]

    def window(a, b):
        return [e for e in est if a <= e['te'] < b]

    def rel(e, key):
        tr = truth_at(e['te'])[key]
        return (e[key] - tr) / tr

    if not est:
        sys.exit('check_vesc_rpemd %s: no estimates' % name)
    first = est[0]
    if abs(rel(first, 'psi_m')) < 0.03:
        errors.append('the first estimate is already at the truth: ψm %+.2f %%' % (100 * rel(first, 'psi_m')))
    report = []
    for a, b in ((30.0, 32.0), (50.0, 52.0)):
        w = window(a, b)
        if not w:
            errors.append('no estimates in %g-%g s' % (a, b))
            continue
        worst = max(abs(rel(e, 'psi_m')) for e in w)
        report.append('ψm %g-%g s: worst %.2f %%' % (a, b, 100 * worst))
        if worst > 0.01:
            errors.append('ψm off by %.2f %% in %g-%g s' % (100 * worst, a, b))
    w = window(38.0, 40.0)
    if w:
        worst = max(abs(rel(e, 'r_s')) for e in w)
        report.append('R_s 38-40 s: worst %.2f %%' % (100 * worst))
        if worst > 0.03:
            errors.append('R_s off by %.2f %% in 38-40 s' % (100 * worst))
    else:
        errors.append('no estimates in 38-40 s')
    late = window(40.0, 70.0)
    for key, tkey in (('T_magnet', 'T_magnet'), ('T_winding', 'T_winding')):
        bad = [e for e in late if not math.isfinite(e[key])]
        if bad or not late:
            errors.append('%s not published (%d of %d estimates not finite)' % (key, len(bad), len(late)))
        elif late:
            report.append('%s %.1f C (plant %.1f C)' % (key, late[-1][key], truth_at(late[-1]['te'])[tkey]))
    before = window(40.0, 45.0)
    after = window(49.0, 54.0)
    if not before or not after or after[-1]['samples'] <= before[-1]['samples']:
        errors.append('no new samples after the silence')
    text = open('%s/%s_listen.txt' % (d, name)).read() + open('%s/%s_rpemd.txt' % (d, name)).read()
    stolen = [int(x) for x in re.findall(r'stolen[_ a-z]*[=: ]+(\d+)', text)]
    report.append('stolen reads counted: %s' % (max(stolen) if stolen else 'none'))
    if not stolen or max(stolen) == 0:
        errors.append('the second poller was not counted')
    if '--prompt-replies' in sys.argv[3:]:
        config = open('%s/%s_config.yaml' % (d, name)).read()  # the configuration rpemd ran (vesc_rpemd.sh)
        timeout_s = float(re.search(r'reply_timeout_s: *([0-9.eE+-]+)', config).group(1))
        rate = re.search(r'estimate_rate_Hz: *([0-9.eE+-]+)', config)
        publish_s = 1.0 / float(rate.group(1)) if rate else 0.1  # rpemd's default: 10 Hz
        check_prompt_replies(emu, text, est, timeout_s, publish_s, report, errors)
    print('check_vesc_rpemd %s: %d estimates; %s' % (name, len(est), '; '.join(report)))
    if errors:
        print('check_vesc_rpemd %s: FAILED\n  %s' % (name, '\n  '.join(errors)))
        sys.exit(1)
    print('check_vesc_rpemd %s: passed' % name)


def replies_sent_later_than(emu, timeout_s):
    """Replies the emulator sent later than timeout_s after their poll's arrival: its histogram's bins that begin
    at or after timeout_s (vesc_emulator.cpp prints `<=EDGE ms COUNT, ..., later COUNT`)."""
    line = re.search(r'replies sent after their poll.s arrival:(.*)', emu).group(1)
    bins = [(float(edge), int(n)) for edge, n in re.findall(r'<=(\d+) ms (\d+)', line)]
    later = int(re.search(r'later (\d+)', line).group(1))
    lower_edges = [0.0] + [edge for edge, _ in bins[:-1]]
    return later + sum(n for lower, (_, n) in zip(lower_edges, bins) if lower >= 1e3 * timeout_s)


def emulator_stalls(emu):
    """The replies the emulator sent 100 ms or more after their poll (vesc_emulator.cpp): the count, and the listed
    ones as (poll's arrival, reply's delay) in seconds of the drive's time, which is the check's."""
    m = re.search(r'stalled \d+ ms or more (\d+) times \([^)]*\):(.*)', emu)
    if not m:
        sys.exit('check_vesc_rpemd: the emulator did not list its stalls')
    return int(m.group(1)), [(float(a), float(b)) for a, b in re.findall(r'(-?[0-9.]+):([0-9.]+)', m.group(2))]


def check_prompt_replies(emu, text, est, timeout_s, publish_s, report, errors):
    """Timeouts only where nobody answered; no chain of late replies after them; stale only where nobody answered."""
    stall_count, stalls = emulator_stalls(emu)
    report.append('the emulator stalled 100 ms or more %d times' % stall_count)

    def emulator_stalled(t):
        return any(a <= t <= a + delay + 2 * publish_s for a, delay in stalls)

    stale = [e['te'] for e in est if e['state'] == 2 and not 45.0 <= e['te'] <= 49.0 and e['te'] < 69.5]
    excused = [t for t in stale if emulator_stalled(t)]
    stale = [t for t in stale if not emulator_stalled(t)]
    if excused:
        report.append('%d estimates stale while the emulator stalled' % len(excused))
    if stale:
        errors.append('%d estimates stale outside the silence, the first at %.1f s' % (len(stale), stale[0]))
    unheard = int(re.search(r'(\d+) unheard while silent', emu).group(1))
    counters = re.findall(r'vesc_polls (\d+) .*?vesc_replies (\d+) vesc_timeouts (\d+) vesc_late_replies (\d+)', text)
    if not counters:
        errors.append('no VESC poller counters in the diagnostics')
        return
    polls, replies, timeouts, late = (int(x) for x in counters[-1])
    rate_hz = polls / 70.0  # the emulator's 70 s
    stalled = replies_sent_later_than(emu, timeout_s)
    allowed = unheard + 2 * math.ceil(rate_hz) + stalled  # the silence, a second at each end, the VM's stalls
    report.append('timeouts %d of %d polls (%d unheard while silent, %d replies the emulator sent later than %g s), '
                  'late replies %d of %d' % (timeouts, polls, unheard, stalled, timeout_s, late, replies))
    if timeouts > allowed:
        errors.append('%d timeouts, more than the %d polls nobody answered in time (silence, a second at each end, '
                      'replies the emulator sent late)' % (timeouts, allowed))
    if late > stalled + 0.01 * replies:
        errors.append('%d of %d replies taken as late, %d sent late by the emulator' % (late, replies, stalled))


if __name__ == '__main__':
    main()
