#!/usr/bin/env python3
"""Checks rpemd (source: signal_map, rpem-native-classic.yaml) on vcan0 (tests/vm/vesc_suite.sh): it started
from the configuration's ψm, which is the plant's before its -8 % step at 1 s (scenarios/can-stream.yaml), and
the estimate it holds once every sample was estimated (its STALE status line after the last running one:
tests/vm/vesc_suite.sh waits for it) follows the step: within 3 % of 0.92 times the start (2 s of drive; the
estimate is still converging, hence not 1 %), the frames reaching the estimator through the map. The last
running line is not the final estimate: lines come once a second while the estimator may still be draining
its queue.

  check_map_rpemd.py RPEMD_OUTPUT
"""
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
last, want = held[0], 0.92 * start
print('check_map_rpemd: psi_m %.4f -> %.4f Wb (plant after the step %.4f, %+.2f %%), %d running status lines'
      % (start, last, want, 100 * (last / want - 1), len(running)))
if abs(last / want - 1) > 0.03:
    sys.exit('check_map_rpemd: psi_m not within 3 % of the plant\'s after its step')
print('check_map_rpemd: passed')
