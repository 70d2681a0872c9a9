#!/usr/bin/env python3
"""Checks rpemd (source: signal_map, rpem-native-classic.yaml) on vcan0 (tests/vm/vesc_suite.sh): the drive
log rpem replay sent as classic frames (scenarios/can-stream.yaml: ψm -8 % at 1 s of 2 s), read back
through the map — the drive's own sample times from its t_sample signal, so however the VM delivered the
frames, the estimator steps by the drive's intervals — must give rpemd the estimate `rpem estimate` gives
offline on the very log that was sent (its last row):

- the estimate rpemd holds once every sample was estimated (its STALE status line after the last running
  one: vesc_suite.sh waits for it) within 0.5 % of the offline one. The frames' resolution (1 mA, 20 mV,
  2π/65536 rad) moves it by < 0.01 % (measured, 2026-11-30); 0.5 % is about 0.13 s of the ≈ 1 s of
  adaptation after the step (the estimate moves ≈ 0.04 Wb/s at the end), so a pipeline that lost or
  mistimed a tenth of the samples fails;
- and the step is seen: both moved at least half way from the start to the plant's ψm after it (the
  estimate is still converging at 2 s of drive; the offline one is +2.8 % from the plant there).

  check_map_rpemd.py RPEMD_OUTPUT OFFLINE_ESTIMATE_CSV
"""
import csv
import re
import sys

lines = open(sys.argv[1]).read().splitlines()
psi = [(l.split()[1], float(re.search(r'psi_m=([0-9.]+) Wb', l).group(1))) for l in lines if 'psi_m=' in l]
start = psi[0][1]
running = [i for i, (state, _) in enumerate(psi) if state == 'running']
if not running:
    sys.exit('check_map_rpemd: rpemd never ran on samples through the map')
held = [p for state, p in psi[running[-1] + 1:] if state == 'STALE']
if not held:
    sys.exit('check_map_rpemd: rpemd was stopped before it had estimated every sample (no STALE line after running)')
rows = list(csv.DictReader(open(sys.argv[2])))
last, offline, plant = held[0], float(rows[-1]['psi_m']), 0.92 * start
print('check_map_rpemd: psi_m %.4f -> %.4f Wb; offline on the sent log %.4f Wb (%+.3f %%); plant after the step '
      '%.4f Wb; %d running status lines' % (start, last, offline, 100 * (last / offline - 1), plant, len(running)))
errors = []
if abs(last / offline - 1) > 0.005:
    errors.append('rpemd\'s psi_m not within 0.5 % of the offline estimate on the same samples')
for name, value in (('rpemd', last), ('offline', offline)):
    if (start - value) < 0.5 * (start - plant):
        errors.append('%s\'s psi_m moved less than half way to the plant\'s after its step' % name)
if errors:
    sys.exit('check_map_rpemd: ' + '; '.join(errors))
print('check_map_rpemd: passed')
