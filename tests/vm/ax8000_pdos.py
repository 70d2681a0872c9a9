#!/usr/bin/env python3
"""An AX8000 (CiA 402) drive's TxPDOs on each SYNC, built from a simulated drive log, as a candump log for
`canplayer` (tests/vm/vesc_suite.sh replays it into rpemd, source: signal_map). Python stdlib only.

The frames are built here with `struct` from the object definitions, not with rpem's encoder: CiA 301
PDOs carry their objects little endian in mapping order, COB-ID 0x180/0x280/0x380/0x480 + node id; REAL32
is IEEE 754 binary32 (struct '<f'), UINT32 '<I', INT32 '<i'. Objects (Beckhoff Information System,
"AX8xxx | Axis module - Object dictionary"; the pages are cited in config/signal-maps/beckhoff-ax8000-cia402.yaml):
  TxPDO1 0x181: 0x606C Velocity actual value, INT32, 0.0001 rpm (mechanical; the default scaling)
  TxPDO2 0x281: 0x3242:05 Id actual, 0x3242:04 Iq actual, REAL32, A
  TxPDO3 0x381: 0x3242:10 Ud actual, 0x3242:0F Uq actual, REAL32, V
  TxPDO4 0x481: 0x6079 DC link circuit voltage, UINT32, mV; 0x32C1:06 Actual motor temperature, REAL32, °C

Values, from the drive log (docs/drive-log.md; `log.dq_columns` and `log.temperatures` on), one SYNC every
`--every` control periods:
  Id, Iq: the measured rotor-frame current at the SYNC (columns i_d, i_q);
  Ud, Uq: the voltage the drive applies in the control period the SYNC opens, in the rotor frame. The log's
    u_d, u_q are the command at ϑ_k, held in the stator frame until t_{k+1} while the rotor turns by
    Δ = ϑ_{k+1} − ϑ_k; its rotor-frame mean is (u_d + j·u_q)·e^{−jΔ/2}·sin(Δ/2)/(Δ/2).
  speed: omega_el / pole pairs in rpm; u_dc; T_winding.

Deliberately bad frames, a known number of each (written to --expect as JSON, with the counters rpemd's
signal-map decoder must then show, docs/sources.md "Counted"):
  unknown ids: frames of other nodes and services (heartbeat 0x701, node 2's TxPDO1 0x182, an LSS 0x7E5)
    sent between two cycles: unknown_id;
  short frames: a cycle's TxPDO3 cut to 4 bytes: wrong_length, and that cycle's trigger finds no voltage:
    incomplete;
  NaN REAL32: a cycle's Iq as the quiet NaN 0x7FC00000: non_finite and incomplete; or a cycle's motor
    temperature (TxPDO4, the trigger) as NaN: non_finite only (the dropped trigger completes nothing).

  ax8000_pdos.py DRIVE_LOG.csv OUT.log --expect OUT.json [--every 8] [--pole-pairs 4] [--node 1]
                 [--averaged OUT_AVG.csv]   (the good samples as an averaged log, for rpem estimate)
"""
import argparse
import csv
import json
import math
import struct

QUIET_NAN32 = struct.pack('<I', 0x7FC00000)


def applied_dq(u_d, u_q, delta):
    """Rotor-frame mean over a control period of a command held in the stator frame while the rotor turns
    by delta: (u_d + j u_q)·e^{-j delta/2}·sinc(delta/2)."""
    half = 0.5 * delta
    gain = 1.0 if abs(half) < 1e-12 else math.sin(half) / half
    c, s = math.cos(half), math.sin(half)
    return gain * (u_d * c + u_q * s), gain * (u_q * c - u_d * s)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('log')
    ap.add_argument('out')
    ap.add_argument('--expect', required=True)
    ap.add_argument('--every', type=int, default=8)
    ap.add_argument('--pole-pairs', type=int, default=4)
    ap.add_argument('--node', type=int, default=1)
    ap.add_argument('--start', type=float, default=1.0, help='first SYNC time in the candump log [s]')
    ap.add_argument('--averaged')
    a = ap.parse_args()

    rows = list(csv.DictReader(open(a.log)))
    need = {'t', 'theta_el', 'omega_el', 'u_dc', 'i_d', 'i_q', 'u_d', 'u_q', 'T_winding'}
    if not need <= set(rows[0]):
        raise SystemExit('ax8000_pdos: %s lacks %s (log.dq_columns and log.temperatures on)' % (a.log, sorted(need - set(rows[0]))))
    period = float(rows[a.every]['t']) - float(rows[0]['t'])  # the SYNC period [s]
    cycles = (len(rows) - 1) // a.every
    n = a.node
    # Which cycles carry a bad frame: spread over the run, never the first few (rpemd's first sample).
    bad_short = {cycles * k // 7 + 3 for k in range(1, 6)}           # 5 short TxPDO3
    bad_nan_iq = {cycles * k // 9 + 5 for k in range(1, 7)}          # 6 NaN Iq
    bad_nan_temp = {cycles * k // 11 + 7 for k in range(1, 5)}       # 4 NaN temperatures (trigger)
    strays = {cycles * k // 13 + 2: k % 3 for k in range(1, 10)}     # 9 unknown ids, between cycles
    assert not (bad_short & bad_nan_iq or bad_short & bad_nan_temp or bad_nan_iq & bad_nan_temp)
    stray_frames = [(0x701, bytes([0x05])), (0x180 + n + 1, struct.pack('<i', 0)), (0x7E5, bytes([0x5E, 0, 0, 0, 0, 0, 0, 0]))]

    count = {'frames': 0, 'samples': 0, 'unknown_id': 0, 'wrong_length': 0, 'incomplete': 0, 'non_finite': 0}
    lines = []
    avg = []

    def put(t, cob, data):
        lines.append('(%.6f) vcan0 %03X#%s\n' % (t, cob, data.hex().upper()))
        count['frames'] += 1

    for k in range(cycles):
        r, r1 = rows[k * a.every], rows[k * a.every + 1]
        t = a.start + k * period
        omega = float(r['omega_el'])
        rpm = omega / a.pole_pairs * 60.0 / (2.0 * math.pi)
        i_d, i_q = float(r['i_d']), float(r['i_q'])
        u_d, u_q = applied_dq(float(r['u_d']), float(r['u_q']), float(r1['theta_el']) - float(r['theta_el']))
        u_dc, temp = float(r['u_dc']), float(r['T_winding'])
        speed_raw = round(rpm / 1e-4)
        pdo1 = struct.pack('<i', speed_raw)
        pdo2 = struct.pack('<ff', i_d, i_q)
        pdo3 = struct.pack('<ff', u_d, u_q)
        pdo4 = struct.pack('<If', round(u_dc * 1000.0), temp)
        good = True
        if k in bad_nan_iq:
            pdo2 = pdo2[:4] + QUIET_NAN32
            count['non_finite'] += 1
            count['incomplete'] += 1
            good = False
        if k in bad_short:
            pdo3 = pdo3[:4]
            count['wrong_length'] += 1
            count['incomplete'] += 1
            good = False
        if k in bad_nan_temp:
            pdo4 = pdo4[:4] + QUIET_NAN32
            count['non_finite'] += 1
            good = False
        # On a 1 Mbit/s bus the four PDOs follow the SYNC about 0.1-0.14 ms apart; the trigger comes last.
        for j, (cob, data) in enumerate(((0x180 + n, pdo1), (0x280 + n, pdo2), (0x380 + n, pdo3), (0x480 + n, pdo4))):
            put(t + j * 150e-6, cob, data)
        if k in strays:
            cob, data = stray_frames[strays[k]]
            put(t + 0.5 * period, cob, data)
            count['unknown_id'] += 1
        if good:
            count['samples'] += 1
            # What the decoder makes of the frames: the REAL32 values as binary32 rounds them.
            d_i, q_i = struct.unpack('<ff', pdo2)
            d_u, q_u = struct.unpack('<ff', pdo3)
            avg.append((t, d_i, q_i, d_u, q_u, speed_raw * 1e-4 * 2.0 * math.pi / 60.0 * a.pole_pairs, u_dc,
                        struct.unpack_from('<f', pdo4, 4)[0]))

    with open(a.out, 'w') as out:
        out.writelines(lines)
    expect = dict(count, cycles=cycles, period_s=period, drive_time_s=cycles * period,
                  bad={'short_pdo3': len(bad_short), 'nan_iq': len(bad_nan_iq), 'nan_temperature': len(bad_nan_temp),
                       'unknown_ids': len(strays)})
    with open(a.expect, 'w') as out:
        json.dump(expect, out, indent=1)
    if a.averaged:
        with open(a.averaged, 'w') as out:
            out.write('t,t_start,i_d,i_q,u_d,u_q,omega_el,u_dc,T_winding\n')
            for row in avg:
                out.write('%.6f,%.6f,%s\n' % (row[0], row[0], ','.join(repr(v) for v in row[1:])))
    print('ax8000_pdos: %d SYNC cycles of %.3g ms (%.1f s), %d frames: %d unknown ids, %d short, %d NaN '
          '(%d Iq, %d temperature); %d good samples'
          % (cycles, period * 1e3, cycles * period, count['frames'], count['unknown_id'], count['wrong_length'],
             count['non_finite'], len(bad_nan_iq), len(bad_nan_temp), count['samples']))


if __name__ == '__main__':
    main()
