#!/usr/bin/env python3
"""Reads bench/vesc_twelve_drives.sh's outputs in DIR: CPU per drive (each rpemd, per thread, and each
emulated VESC) over the measured window; each drive's poll and sample rates over the window from rpemd's own
counters (its status lines at the window's start and end, so each rate is uncertain by about one status
interval, 1 s, over the window); how far each emulator's drive time ended behind the host; and the bus load
the frames captured after the window reach on a classic 1 Mbit/s bus.

Frame bits as in can/src/bus_load.cpp (frame_bits, classic): 54 stuffable bits for a 29-bit id plus 8 per
data byte, worst-case stuffing (n - 1) // 4, 13 bits of tail — the same count as docs/benchmarks.md's
table, so the load measured here is comparable with its 70 % target.

  vesc_twelve_drives.py DIR [--rate HZ] [--loop S] [--measurement-rate HZ] [--idle-step S]
"""
import argparse
import collections
import re

USER_HZ = 100  # /proc/PID/task/TID/stat's utime and stime unit on x86 Linux


def snapshot(path, roles):
    """{(role, drive, tid): (comm, ticks)} from lines "/proc/PID/task/TID/stat (comm) utime stime"."""
    rows = {}
    for line in open(path):
        f = line.split()
        if len(f) != 4:
            continue
        m = re.match(r'/proc/(\d+)/task/(\d+)/stat', f[0])
        if not m or m.group(1) not in roles:
            continue
        role, drive = roles[m.group(1)]
        rows[(role, drive, m.group(2))] = (f[1].strip('()'), int(f[2]) + int(f[3]))
    return rows


def contexts(path):
    """{(pid, tid): voluntary context switches} from lines "/proc/PID/task/TID/status N"."""
    out = {}
    for line in open(path):
        m = re.match(r'/proc/(\d+)/task/(\d+)/status (\d+)', line)
        if m:
            out[(m.group(1), m.group(2))] = int(m.group(3))
    return out


VESC_COUNTERS = re.compile(r'vesc polls (\d+) replies (\d+) timeouts (\d+) late (\d+) unrequested (\d+)')


def vesc_counters(path):
    """[(polls, samples, timeouts, late, unrequested) or None] per drive, from rpemd status lines
    (docs/rpemd.md: "replies" there are the samples delivered)."""
    out = []
    for line in open(path):
        m = VESC_COUNTERS.search(line)
        out.append(tuple(int(g) for g in m.groups()) if m else None)
    return out


def frame_bits(extended, data_bytes):
    stuffable = (54 if extended else 34) + 8 * data_bytes
    return stuffable + (stuffable - 1) // 4 + 13


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('dir')
    ap.add_argument('--rate', type=float, default=56.0)
    ap.add_argument('--loop', default='5.0e-3', help="rpemd's loop.period_s (for the report)")
    ap.add_argument('--measurement-rate', default='10', help="rpemd's lcm.measurement_rate_Hz (for the report)")
    ap.add_argument('--idle-step', default='0.01', help="the emulators' --idle-step (for the report)")
    a = ap.parse_args()
    d = a.dir
    t0 = float(open(d + '/t_start').read())
    t1 = float(open(d + '/t_end').read())
    window = t1 - t0
    roles = {}
    for role, name in (('rpemd', 'rpemd.pids'), ('sim', 'sim.pids')):
        for i, pid in enumerate(open('%s/%s' % (d, name)).read().split()):
            roles[pid] = (role, i + 1)
    start, end = snapshot(d + '/start.txt', roles), snapshot(d + '/end.txt', roles)
    per_thread = collections.defaultdict(list)   # (role, comm) -> [% of a core per drive]
    per_drive = collections.defaultdict(dict)    # role -> drive -> % of a core
    for key, (comm, ticks) in end.items():
        if key not in start:
            continue
        pct = 100.0 * (ticks - start[key][1]) / USER_HZ / window
        role, drive, _ = key
        per_thread[(role, comm)].append(pct)
        per_drive[role][drive] = per_drive[role].get(drive, 0.0) + pct
    where = open(d + '/where').read().strip()
    cpus = open(d + '/nproc').read().strip() if _exists(d + '/nproc') else '?'
    clock = open(d + '/clocksource').read().strip() if _exists(d + '/clocksource') else '?'
    drives = len(open(d + '/rpemd.pids').read().split())
    print('vesc_twelve_drives: %s, %s CPUs, clocksource %s; %d drives polled at %g Hz each; rpemd loop %s s, '
          'measurements %s Hz; emulator idle step %s s; window %.1f s'
          % (where, cpus, clock, drives, a.rate, a.loop, a.measurement_rate, a.idle_step, window))
    # All CPUs over the window (/proc/stat's first line): what the measured processes leave.
    if _exists(d + '/start.stat') and _exists(d + '/end.stat'):
        s0 = [int(x) for x in open(d + '/start.stat').read().split()[1:]]
        s1 = [int(x) for x in open(d + '/end.stat').read().split()[1:]]
        delta = [y - x for x, y in zip(s0, s1)]
        total = sum(delta[:8])
        names = ('user', 'nice', 'system', 'idle', 'iowait', 'irq', 'softirq', 'steal')
        print('  all CPUs over the window: ' + ', '.join('%s %.1f %%' % (n, 100.0 * v / total)
                                                      for n, v in zip(names, delta[:8]) if v))
    for role in ('rpemd', 'sim'):
        v = sorted(per_drive[role].values())
        if v:
            print('  %-6s per drive: mean %.2f %%, min %.2f %%, max %.2f %% of a core; all %d: %.1f %%'
                  % ('rpemd' if role == 'rpemd' else 'sim', sum(v) / len(v), v[0], v[-1], len(v), sum(v)))
    # Wake-ups: voluntary context switches per second, per thread.
    comm_of = {tid: comm for (role, drive, tid), (comm, _) in end.items()}
    wakeups = collections.defaultdict(list)
    c0, c1 = contexts(d + '/start.ctx'), contexts(d + '/end.ctx')
    for key, n in c1.items():
        pid, tid = key
        if key in c0 and pid in roles:
            wakeups[(roles[pid][0], comm_of.get(tid, '?'))].append((n - c0[key]) / window)
    for (role, comm), v in sorted(per_thread.items()):
        w = wakeups.get((role, comm), [])
        print('    %-5s thread %-16s mean %.2f %%, max %.2f %% (%d threads); %.0f wake-ups/s each'
              % (role, comm, sum(v) / len(v), max(v), len(v), sum(w) / len(w) if w else float('nan')))
    # The bus after the window: candump -L lines "(t) vcan0 ID#DATA".
    bits = 0
    frames = 0
    captured_polls = collections.Counter()
    times = []
    for line in open(d + '/bus.log'):
        m = re.match(r'\((\d+\.\d+)\) \S+ ([0-9A-Fa-f]+)#([0-9A-Fa-f]*)', line)
        if not m:
            continue
        ident, data = m.group(2), m.group(3)
        extended = len(ident) == 8
        bits += frame_bits(extended, len(data) // 2)
        frames += 1
        times.append(float(m.group(1)))
        i = int(ident, 16)
        if extended and (i >> 8) == 8 and len(data) >= 6 and int(data[4:6], 16) == 50:
            captured_polls[i & 0xFF] += 1
    span = times[-1] - times[0] if len(times) > 1 else window
    print('  bus (captured after the window): %d frames in %.1f s, %.0f frames/s; %.1f %% of a classic 1 Mbit/s '
          'bus (worst-case stuffing)'
          % (frames, span, frames / span, 100.0 * bits / span / 1e6))
    # Each rpemd's own counts over the window. A poll is answered within reply_timeout_s (0.9 periods) or
    # times out: not timed out = polls - timeouts. That is not "in time" when the controller answers seconds
    # behind: a stale reply arriving while a later poll is out counts as that poll's answer (the emulators'
    # reply delays below are the measure). Samples also count replies after a timeout (late, unrequested).
    if _exists(d + '/start.vesc') and _exists(d + '/end.vesc'):
        span_c = float(open(d + '/t_vesc_end').read()) - float(open(d + '/t_vesc_start').read())
        c0, c1 = vesc_counters(d + '/start.vesc'), vesc_counters(d + '/end.vesc')
        rows = []
        for i, (x, y) in enumerate(zip(c0, c1)):
            if x is None or y is None:
                print('  drive %d: no rpemd status line at the window\'s start or end' % (i + 1))
                continue
            n_polls, n_samples, n_timeouts, n_late, n_unrequested = (y[k] - x[k] for k in range(5))
            rows.append((i + 1, n_polls / span_c, (n_polls - n_timeouts) / span_c, n_samples / span_c,
                         n_late / span_c, n_unrequested / span_c))
        print('  rpemd counters over %.1f s (status lines read just before and after the window):' % span_c)
        for drive, p, ok, smp, late, unreq in rows:
            print('  drive %2d: polls %.1f Hz, not timed out %.1f Hz (%.1f %%), samples %.1f Hz '
                  '(late %.1f Hz, unrequested %.1f Hz)' % (drive, p, ok, 100.0 * ok / p if p else float('nan'),
                                                           smp, late, unreq))
        if rows:
            p = [r[1] for r in rows]
            ok = [r[2] for r in rows]
            smp = [r[3] for r in rows]
            print('  per drive: polls %.1f-%.1f Hz (asked %g Hz), not timed out %.1f-%.1f Hz (mean %.1f Hz, '
                  '%.1f %% of all polls), samples %.1f-%.1f Hz'
                  % (min(p), max(p), a.rate, min(ok), max(ok), sum(ok) / len(ok), 100.0 * sum(ok) / sum(p),
                     min(smp), max(smp)))
    # Each rpemd's totals over its whole run (its last status line).
    answered = []
    for i in range(1, drives + 1):
        c = [x for x in vesc_counters('%s/rpemd%d.txt' % (d, i)) if x]
        if c:
            answered.append(c[-1])
    if answered:
        p, r, t, late, unreq = (sum(x[k] for x in answered) for k in range(5))
        print('  rpemd over the whole run (%d drives): %d polls, %d not timed out, %d timeouts; %d samples '
              '(%d late, %d unrequested)' % (drives, p, p - t, t, r, late, unreq))
    # How far each emulator's drive time ended behind the host (its exit line).
    lags, pace = [], []
    for i in range(1, drives + 1):
        if _exists('%s/emu%d.txt' % (d, i)):
            m = re.search(r'stopped at ([0-9.]+) s drive time \(([-0-9.]+) s behind the host\)',
                          open('%s/emu%d.txt' % (d, i)).read())
            if m:
                drive_s, lag_s = float(m.group(1)), float(m.group(2))
                lags.append(lag_s)
                pace.append(drive_s / (drive_s + lag_s))
    if lags:
        print('  emulators: drive time ended %.3f-%.3f s behind the host; their drives ran at %.2f-%.2f of real '
              'time over their run (%d emulators)' % (min(lags), max(lags), min(pace), max(pace), len(lags)))
    # The emulators' own reply delays over their run (poll's kernel receive time to the reply's last frame).
    classes = collections.Counter()
    latest = 0.0
    for i in range(1, drives + 1):
        if not _exists('%s/emu%d.txt' % (d, i)):
            continue
        text = open('%s/emu%d.txt' % (d, i)).read()
        for edge, n in re.findall(r'<=(\d+) ms (\d+),', text):
            classes[int(edge)] += int(n)
        m = re.search(r'later (\d+); the latest ([0-9.]+) s', text)
        if m:
            classes['later'] += int(m.group(1))
            latest = max(latest, float(m.group(2)))
    total = sum(classes.values())
    if total:
        cumulative = 0
        parts = []
        for edge in sorted(k for k in classes if k != 'later'):
            cumulative += classes[edge]
            parts.append('<=%d ms %.1f %%' % (edge, 100.0 * cumulative / total))
        print('  emulators\' replies (%d over the whole run), sent after the poll arrived: %s; the latest %.3f s'
              % (total, ', '.join(parts), latest))
    if captured_polls:
        rates = sorted(n / span for n in captured_polls.values())
        print('  captured polls per controller: %d controllers, %.1f-%.1f Hz (asked %g Hz); %.0f bits per poll '
              'and reply' % (len(captured_polls), rates[0], rates[-1], a.rate, bits / sum(captured_polls.values())))


def _exists(p):
    try:
        open(p).close()
        return True
    except OSError:
        return False


if __name__ == '__main__':
    main()
