#!/usr/bin/env python3
"""Checks an averaged log written by `rpem record --averaged-out` against the drive log that was sent,
with its own Clarke/Park and no project code.

- With --rate (native telemetry averaged over windows on the drive's clock): every window's i_d, i_q is
  the mean of the sent samples' rotor-frame currents whose times lie in [t_start, t), and u_d, u_q the
  mean over those periods of the held phase voltages turned into the rotor frame along the angle's sweep
  (midpoint quadrature); window lengths 1/rate.
- Without (a signal map of instantaneous samples, stamped with the drive's own time, its t_sample signal):
  the k-th recorded sample is the k-th sent row in the rotor frame, at the row's time (the drive's clock
  counts µs) however the frames were delayed on the way.
- With --temperatures (native telemetry whose drive sends its temperature frame every 100 ms): a window's
  T_winding is the mean of the readings it received — each within half a step (0.1 °C per bit) of the sent
  values over the window widened by three samples (the frame goes with the next sample received), one window
  with a reading per 100 ms of samples; without a sent reading, no window has one.

  check_averaged_record.py SENT.csv AVERAGED.csv [--rate HZ] [--temperatures]
"""
import argparse
import csv
import math
import sys


def rotor(a, b, c, th):
    al = (2 * a - b - c) / 3
    be = (b - c) / math.sqrt(3)
    return math.cos(th) * al + math.sin(th) * be, -math.sin(th) * al + math.cos(th) * be


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('sent')
    ap.add_argument('averaged')
    ap.add_argument('--rate', type=float)
    ap.add_argument('--temperatures', action='store_true')
    a = ap.parse_args()
    sent = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(open(a.sent))]
    avg = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(open(a.averaged))]
    if len(avg) < 50:
        sys.exit('check_averaged_record: only %d samples in %s' % (len(avg), a.averaged))
    errors, worst_i, worst_u = [], 0.0, 0.0
    if a.rate:
        # per period k: rotor-frame current at its start, mean rotor-frame voltage over [t_k, t_k+1]
        cyc = []
        for r, n in zip(sent, sent[1:]):
            i = rotor(r['i_a'], r['i_b'], r['i_c'], r['theta_el'])
            sweep = math.remainder(n['theta_el'] - r['theta_el'], 2 * math.pi)
            ud = uq = 0.0
            for k in range(32):
                d, q = rotor(r['u_a'], r['u_b'], r['u_c'], r['theta_el'] + sweep * (k + 0.5) / 32)
                ud += d / 32
                uq += q / 32
            cyc.append((r['t'], i[0], i[1], ud, uq))
        for w in avg:
            inside = [c for c in cyc if w['t_start'] - 1e-7 <= c[0] < w['t'] - 1e-7]
            if not inside:
                errors.append('window [%g, %g] holds no sent period' % (w['t_start'], w['t']))
                continue
            n = len(inside)
            m = [sum(c[j] for c in inside) / n for j in range(1, 5)]
            di = max(abs(w['i_d'] - m[0]), abs(w['i_q'] - m[1]))
            du = max(abs(w['u_d'] - m[2]), abs(w['u_q'] - m[3]))
            worst_i, worst_u = max(worst_i, di), max(worst_u, du)
            length = w['t'] - w['t_start']
            if abs(length - 1 / a.rate) > 1.5e-4:  # closes at the first period boundary after 1/rate
                errors.append('window of %.4f s at %g' % (length, w['t']))
        # telemetry resolution: 1 mA and 10 mV per phase (can/rpem_telemetry.dbc); the quadrature ~1e-4 V
        if worst_i > 0.003 or worst_u > 0.05:
            errors.append('worst window error %.4f A, %.4f V' % (worst_i, worst_u))
        expected = (sent[-1]['t'] - sent[0]['t']) * a.rate
        if len(avg) < 0.95 * expected - 1:
            errors.append('%d windows, expected about %.0f' % (len(avg), expected))
    else:
        rot = [rotor(r['i_a'], r['i_b'], r['i_c'], r['theta_el']) for r in sent]
        # the first recorded sample may be a later row (the recorder started late): find it
        best = min(range(0, 50), key=lambda s: abs(rot[s][1] - avg[0]['i_q']) + abs(rot[s][0] - avg[0]['i_d']))
        for k, w in enumerate(avg):
            if best + k >= len(rot):
                errors.append('more samples than sent rows')
                break
            d, q = rot[best + k]
            worst_i = max(worst_i, abs(w['i_d'] - d), abs(w['i_q'] - q))
            step = (w['t'] - avg[0]['t']) - (sent[best + k]['t'] - sent[best]['t'])
            if abs(step) > 1.5e-6:
                errors.append('sample %d at %+.6f s from the first, the drive sent it at %+.6f s'
                              % (k, w['t'] - avg[0]['t'], sent[best + k]['t'] - sent[best]['t']))
                break
            if w['t'] != w['t_start']:
                errors.append('an instantaneous sample with a window at %g' % w['t'])
                break
        if worst_i > 0.003:
            errors.append('worst sample error %.4f A' % worst_i)
        if len(avg) < 0.98 * (len(sent) - best):
            errors.append('%d samples of %d sent rows' % (len(avg), len(sent) - best))
    if a.temperatures:
        check_temperatures(sent, avg, errors)
    print('check_averaged_record: %s: %d samples, worst |i| error %.4f A, |u| error %.4f V'
          % (a.averaged, len(avg), worst_i, worst_u))
    if errors:
        print('check_averaged_record: FAILED\n  ' + '\n  '.join(errors[:20]))
        sys.exit(1)
    print('check_averaged_record: passed')


def check_temperatures(sent, avg, errors):
    half = 0.05
    period = sent[1]['t'] - sent[0]['t']
    for column in ('T_winding', 'T_coolant'):
        got = [w for w in avg if math.isfinite(w.get(column, math.nan))]
        values = [(r['t'], r[column]) for r in sent if math.isfinite(r.get(column, math.nan))]
        if not values:
            if got:
                errors.append('%s %g in the window ending %g s, none sent' % (column, got[0][column], got[0]['t']))
            continue
        for w in got:
            near = [v for t, v in values if w['t_start'] - 3 * period - 1e-7 <= t <= w['t'] + 3 * period + 1e-7]
            if not near or not min(near) - half - 1e-9 <= w[column] <= max(near) + half + 1e-9:
                errors.append('%s %g in the window [%g, %g]; sent around it: %s'
                              % (column, w[column], w['t_start'], w['t'], near[:8]))
        span = sent[-1]['t'] - sent[0]['t']
        frames = int(span / 0.1 + 1e-9) + 1
        if not frames - 1 <= len(got) <= frames:
            errors.append('%d windows with a %s reading over %g s of samples (one every 100 ms: %d or %d)'
                          % (len(got), column, span, frames - 1, frames))
        else:
            print('check_averaged_record: %d windows with a %s reading, each within half a step of those sent'
                  % (len(got), column))


if __name__ == '__main__':
    main()
