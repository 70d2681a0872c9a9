#!/usr/bin/env python3
"""Checks rpemd (source: signal_map, config/signal-maps/beckhoff-ax8000-cia402.yaml) fed over vcan0 with AX8000
TxPDOs (tests/vm/vesc_suite.sh; frames from tests/vm/ax8000_pdos.py, drive tests/vm/ax8000-vcan.yaml):

- it starts from the configuration (config/beckhoff-am8141.yaml: ψm 0.042 Wb, R_s 0.51 Ω), off the plant's
  (ψm +5 %, R_s −8 %): its first estimate is more than 3 % off the plant's ψm;
- its final estimates (the drive ends at standstill after a speed phase: ψm held from there, R_s adapting)
  are within 1 % (ψm) and 3 % (R_s) of the plant's at the end of the drive (the truth CSV's last row);
- the map decoder's counters in rpemd's diagnostics (`rpem listen --diagnostics`, the `signal_map:` line)
  equal what the script sent: every frame, the unknown ids, the short frames, the NaN values and the
  incomplete cycles they caused — exactly, and no kernel drops;
- the estimator stepped on every good sample (its sample count = the cycles without a bad frame).

  check_ax8000_rpemd.py DIR     (DIR: ax8000_pdos.json, ax8000_truth.csv, ax8000_est.csv, ax8000_listen.txt)
"""
import csv
import json
import re
import sys


def last_row(path):
    row = None
    for row in csv.DictReader(open(path)):
        pass
    return row


def main():
    d = sys.argv[1]
    want = json.load(open('%s/ax8000_pdos.json' % d))
    plant = last_row('%s/ax8000_truth.csv' % d)
    plant_psi, plant_rs = float(plant['psi_m']), float(plant['r_s'])
    est = list(csv.DictReader(open('%s/ax8000_est.csv' % d)))
    errors = []
    if not est:
        sys.exit('check_ax8000_rpemd: no estimates heard')
    first, last = est[0], est[-1]
    psi0, psi, rs = float(first['psi_m']), float(last['psi_m']), float(last['r_s'])
    e_psi0 = psi0 / plant_psi - 1
    e_psi, e_rs = psi / plant_psi - 1, rs / plant_rs - 1
    samples = max(int(float(r['samples'])) for r in est)
    print('check_ax8000_rpemd: %d estimates over %.1f s of drive (%d SYNC cycles); psi_m %.5f -> %.5f Wb '
          '(plant %.5f: %+.2f %% -> %+.3f %%), r_s %.4f Ohm (plant %.4f: %+.3f %%), %d samples estimated'
          % (len(est), want['drive_time_s'], want['cycles'], psi0, psi, plant_psi, 100 * e_psi0, 100 * e_psi, rs,
             plant_rs, 100 * e_rs, samples))
    if abs(e_psi0) < 0.03:
        errors.append('the first estimate is already at the plant: psi_m %+.2f %%' % (100 * e_psi0))
    if abs(e_psi) > 0.01:
        errors.append('psi_m off the plant by %+.3f %% (limit 1 %%)' % (100 * e_psi))
    if abs(e_rs) > 0.03:
        errors.append('r_s off the plant by %+.3f %% (limit 3 %%)' % (100 * e_rs))
    if samples != want['samples']:
        errors.append('the estimator stepped %d samples, the frames carried %d good ones' % (samples, want['samples']))

    lines = re.findall(r'diag \d+ signal_map: (.*)', open('%s/ax8000_listen.txt' % d).read())
    if not lines:
        errors.append('no signal_map diagnostics heard')
    else:
        got = {k: int(v) for k, v in re.findall(r'([a-z_]+) (\d+)', lines[-1])}
        print('check_ax8000_rpemd: counters %s; sent %s' % (
            ' '.join('%s %d' % kv for kv in got.items()),
            ' '.join('%s %d' % (k, want[k]) for k in ('frames', 'unknown_id', 'wrong_length', 'incomplete', 'non_finite'))))
        for key in ('frames', 'unknown_id', 'wrong_length', 'incomplete', 'non_finite'):
            if got.get(key) != want[key]:
                errors.append('%s: rpemd counted %s, the script sent %d' % (key, got.get(key), want[key]))
        if got.get('kernel_drops', 0) != 0:
            errors.append('the kernel dropped %d frames' % got['kernel_drops'])
    if errors:
        print('check_ax8000_rpemd: FAILED\n  %s' % '\n  '.join(errors))
        sys.exit(1)
    print('check_ax8000_rpemd: passed')


if __name__ == '__main__':
    main()
