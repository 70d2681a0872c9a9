#!/usr/bin/env python3
"""Reads bench/vesc_twelve_drives.sh's outputs in DIR: CPU per drive (each rpemd, per thread, and each
emulated VESC) over the measured window, and the bus load its frames reach on a classic 1 Mbit/s bus.

Frame bits as in can/src/bus_load.cpp (frame_bits, classic): 54 stuffable bits for a 29-bit id plus 8 per
data byte, worst-case stuffing (n - 1) // 4, 13 bits of tail — the same count as docs/benchmarks.md's
table, so the load measured here is comparable with its 70 % target.

  vesc_twelve_drives.py DIR [--rate HZ]
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


def frame_bits(extended, data_bytes):
    stuffable = (54 if extended else 34) + 8 * data_bytes
    return stuffable + (stuffable - 1) // 4 + 13


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('dir')
    ap.add_argument('--rate', type=float, default=56.0)
    ap.add_argument('--loop', default='1.0e-3', help="rpemd's loop.period_s (for the report)")
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
    print('vesc_twelve_drives: %s, %s CPUs; 12 drives polled at %g Hz each, rpemd loop %s s; window %.1f s'
          % (where, cpus, a.rate, a.loop, window))
    for role in ('rpemd', 'sim'):
        v = sorted(per_drive[role].values())
        if v:
            print('  %-6s per drive: mean %.2f %%, min %.2f %%, max %.2f %% of a core; all 12: %.1f %%'
                  % ('rpemd' if role == 'rpemd' else 'sim', sum(v) / len(v), v[0], v[-1], sum(v)))
    # Wake-ups: voluntary context switches per second, per thread.
    comm_of = {tid: comm for (role, drive, tid), (comm, _) in end.items()}
    wakeups = collections.defaultdict(list)
    c0, c1 = contexts(d + '/start.ctx'), contexts(d + '/end.ctx')
    for key, n in c1.items():
        pid, tid = key
        if key in c0 and pid in roles and roles[pid][0] == 'rpemd':
            wakeups[comm_of.get(tid, '?')].append((n - c0[key]) / window)
    for (role, comm), v in sorted(per_thread.items()):
        if role == 'rpemd':
            w = wakeups.get(comm, [])
            print('    thread %-16s mean %.2f %%, max %.2f %% (%d threads); %.0f wake-ups/s each'
                  % (comm, sum(v) / len(v), max(v), len(v), sum(w) / len(w) if w else float('nan')))
    # The bus over the window: candump -L lines "(t) vcan0 ID#DATA".
    bits = 0
    frames = 0
    polls = collections.Counter()
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
            polls[i & 0xFF] += 1
    span = times[-1] - times[0] if len(times) > 1 else window
    print('  bus: %d frames in %.1f s, %.0f frames/s; %.1f %% of a classic 1 Mbit/s bus (worst-case stuffing)'
          % (frames, span, frames / span, 100.0 * bits / span / 1e6))
    # Each rpemd's own count of its polls and replies (its last status line).
    answered = []
    for i in range(1, 13):
        lines = [l for l in open('%s/rpemd%d.txt' % (d, i)) if '[vesc polls' in l]
        if lines:
            m = re.search(r'vesc polls (\d+) replies (\d+) timeouts (\d+)', lines[-1])
            answered.append((int(m.group(1)), int(m.group(2)), int(m.group(3))))
    if answered:
        p, r, t = (sum(x[k] for x in answered) for k in range(3))
        print('  rpemd over the run (12 drives): %d polls, %d replies became samples, %d timeouts' % (p, r, t))
    if polls:
        rates = sorted(n / span for n in polls.values())
        print('  polls per controller: %d controllers, %.1f-%.1f Hz (asked %g Hz); %.0f bits per poll and reply'
              % (len(polls), rates[0], rates[-1], a.rate, bits / sum(polls.values())))


def _exists(p):
    try:
        open(p).close()
        return True
    except OSError:
        return False


if __name__ == '__main__':
    main()
