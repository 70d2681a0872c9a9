#!/usr/bin/env python3
"""Checks a candump -L capture of the emulated VESC (rpem sim --vesc) polled by cangen, decoding it with
no project code, from docs/can-vesc.md alone (which cites vedderb/bldc: comm_can.c comm_can_send_buffer,
decode_msg, comm_can_send_status1..6; commands.c commands_process_packet; buffer.c; crc.c crc16):

- every poll outside the silent interval is answered: FILL_RX_BUFFER frames with consecutive offsets and a
  PROCESS_RX_BUFFER whose length and CRC-16/XMODEM (binascii.crc_hqx) match, from the polled controller;
- the reply decodes (mask 0x001801B3) to values consistent with the simulator's truth and with the
  steady-state machine equations (u_d = R i_d - w L i_q, u_q = R i_q + w (L i_d + psi_m)) at the truth's
  parameters: VESC's scalings and the rotor-frame voltage are right, not only the framing;
- status broadcasts 1, 4, 5 come at ~50 Hz and 2, 3, 6 at ~5 Hz, with ERPM, temperatures and V_in
  matching the replies;
- during the silent interval the controller sends nothing.

  check_vesc_capture.py CAPTURE TRUTH EMULATOR_LOG --controller 17 --poller 0x7D --silent T0 T1

Times are the emulator's own, from what it printed (EMULATOR_LOG, its stderr): its origin on CLOCK_REALTIME, the
clock candump stamps frames with, and the moments it actually went silent and came back. --silent is what the
emulator was asked for; the moments it printed must match it. (The first status frame is no origin: under TCG
it can leave tens of ms late, which once moved frames after the silence into it.)
"""
import argparse
import binascii
import bisect
import csv
import math
import re
import struct
import sys

FILL, FILL_LONG, PROCESS, SHORT = 5, 6, 7, 8
STATUS = {9: 1, 14: 2, 15: 3, 16: 4, 27: 5, 58: 6}


def frames(path):
    for line in open(path):
        parts = line.split()
        if len(parts) < 3 or '#' not in parts[2]:
            continue
        ident, data = parts[2].split('#', 1)
        if len(ident) != 8:  # VESC frames are extended (8 hex digits in candump -L)
            continue
        yield float(parts[0].strip('()')), int(ident, 16), bytes.fromhex(data)


def emulator_times(path, asked):
    """(origin on CLOCK_REALTIME [s], went silent [s], came back [s]) from rpem sim's stderr."""
    text = open(path).read()
    origin = re.search(r'rpem sim: t = 0 at CLOCK_REALTIME ([0-9.]+) s', text)
    silent = re.search(r'rpem sim: VESC \d+ silent at ([0-9.]+) s', text)
    back = re.search(r'rpem sim: VESC \d+ back at ([0-9.]+) s', text)
    if not (origin and silent and back):
        sys.exit('check_vesc_capture: %s lacks the emulator\'s origin, silence or return' % path)
    s0, s1 = float(silent.group(1)), float(back.group(1))
    # The emulator looks at its clock at least every millisecond; 0.5 s leaves room for a TCG stall at the edge
    # (the frames are judged against the printed moments, not the asked ones).
    if not (abs(s0 - asked[0]) < 0.5 and abs(s1 - asked[1]) < 0.5):
        sys.exit('check_vesc_capture: silent %.3f-%.3f s, asked for %g-%g s' % (s0, s1, asked[0], asked[1]))
    return float(origin.group(1)), s0, s1


def decode_reply(p):
    """[50][mask][fields]; the estimator mask 0x001801B3 only."""
    if p[0] != 50:
        raise ValueError('not COMM_GET_VALUES_SELECTIVE')
    mask = struct.unpack('>I', p[1:5])[0]
    if mask != 0x001801B3:
        raise ValueError('mask %08X' % mask)
    t_fet, t_mot, i_d, i_q, rpm, vin, v_d, v_q = struct.unpack('>hhiiihii', p[5:])
    return dict(t_fet=t_fet / 10, t_motor=t_mot / 10, i_d=i_d / 100, i_q=i_q / 100, erpm=float(rpm), vin=vin / 10,
                v_d=v_d / 1000, v_q=v_q / 1000)


def check_record(avg_path, truth_path, rate):
    """Each window of the recorded log against the truth's steady state (speed held from 0 to 12 s)."""
    errors = []
    rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(open(avg_path))]
    truth = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(open(truth_path))]
    steady = [r for r in truth if 1.0 < r['t'] < 11.0]
    mean = {k: sum(r[k] for r in steady) / len(steady) for k in ('i_q', 'omega_el', 'psi_m', 'r_s', 'l_d', 'T_winding')}
    span = rows[-1]['t'] - rows[0]['t_start'] if rows else 0.0
    if len(rows) < 0.25 * span * rate or span < 5.0:  # under TCG many polls time out (slow replies)
        errors.append('record: %d windows in %.1f s at %g Hz' % (len(rows), span, rate))
    lengths = sorted(r['t'] - r['t_start'] for r in rows)
    median = lengths[len(lengths) // 2] if lengths else 0.0
    if not 0.8 / rate < median < 4.0 / rate:  # windows run read to read; timeouts under TCG lengthen them
        errors.append('record: median window %.5f s at %g Hz' % (median, rate))
    u_q = mean['r_s'] * mean['i_q'] + mean['omega_el'] * mean['psi_m']
    worst = dict(i_q=0.0, w=0.0, u_q=0.0)
    for r in rows:
        worst['i_q'] = max(worst['i_q'], abs(r['i_q'] - mean['i_q']) / abs(mean['i_q']))
        worst['w'] = max(worst['w'], abs(r['omega_el'] - mean['omega_el']) / abs(mean['omega_el']))
        worst['u_q'] = max(worst['u_q'], abs(r['u_q'] - u_q) / abs(u_q))
        if abs(r['T_drive'] - 40.0) > 0.11 or abs(r['T_winding'] - mean['T_winding']) > 1.0 or abs(r['u_dc'] - 48) > 0.5:
            errors.append('record: temperatures or u_dc off at t %.3f: %s' % (r['t'], r))
            break
    for k, lim in (('i_q', 0.05), ('w', 0.02), ('u_q', 0.03)):
        if worst[k] > lim:
            errors.append('record: %s off the steady state by %.2f %%' % (k, 100 * worst[k]))
    print('check_vesc_capture: record %s: %d windows, median %.2f ms; worst i_q %.2f %%, omega %.2f %%, u_q %.2f %%'
          % (avg_path, len(rows), 1e3 * median, 100 * worst['i_q'], 100 * worst['w'], 100 * worst['u_q']))
    return errors


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('capture')
    ap.add_argument('truth')
    ap.add_argument('emulator_log')
    ap.add_argument('--controller', type=int, required=True)
    ap.add_argument('--poller', type=lambda s: int(s, 0), required=True)
    ap.add_argument('--silent', type=float, nargs=2, required=True)
    ap.add_argument('--record', nargs=2, metavar=('AVG', 'TRUTH'),
                    help='also check an averaged log rpem record wrote from the emulator at steady speed')
    ap.add_argument('--record-rate', type=float, default=200.0)
    a = ap.parse_args()
    errors = []
    if a.record:
        errors += check_record(a.record[0], a.record[1], a.record_rate)
    cid, me = a.controller, a.poller
    polls, replies, statuses, from_ctrl = [], [], {n: [] for n in range(1, 7)}, []
    buf, fill = bytearray(), 0
    for t, ident, d in frames(a.capture):
        node, packet = ident & 0xFF, ident >> 8
        if packet == SHORT and node == cid:
            polls.append(t)
        elif packet in (FILL, FILL_LONG) and node == me:
            off = d[0] if packet == FILL else (d[0] << 8 | d[1])
            chunk = d[1:] if packet == FILL else d[2:]
            if off == 0:
                buf, fill = bytearray(), 0
            if off != fill:
                errors.append('fill at %d, expected %d (t %.4f)' % (off, fill, t))
            buf += chunk
            fill += len(chunk)
        elif packet == PROCESS and node == me:
            sender, send, length, crc = d[0], d[1], d[2] << 8 | d[3], d[4] << 8 | d[5]
            if sender != cid or send != 1:
                errors.append('process from %d send %d' % (sender, send))
            if length != fill or binascii.crc_hqx(bytes(buf), 0) != crc:
                errors.append('reply at %.4f: length %d/%d, crc %04X/%04X' % (t, length, fill, crc,
                                                                          binascii.crc_hqx(bytes(buf), 0)))
            else:
                replies.append((t, decode_reply(bytes(buf))))
            buf, fill = bytearray(), 0
            from_ctrl.append(t)
        elif packet in STATUS and node == cid:
            n = STATUS[packet]
            if n == 1:
                erpm, cur, duty = struct.unpack('>ihh', d)
                statuses[1].append((t, dict(erpm=erpm)))
            elif n == 4:
                tf, tm, cin, pos = struct.unpack('>hhhh', d)
                statuses[4].append((t, dict(t_fet=tf / 10, t_motor=tm / 10)))
            elif n == 5:
                tacho, vin, _ = struct.unpack('>ihh', d)
                statuses[5].append((t, dict(vin=vin / 10, tacho=tacho)))
            else:
                statuses[n].append((t, {}))
            from_ctrl.append(t)
    if not statuses[1]:
        sys.exit('check_vesc_capture: no STATUS frame from controller %d' % cid)
    t0, s0, s1 = emulator_times(a.emulator_log, a.silent)
    first_status_s = statuses[1][0][0] - t0  # cancom_status_thread's first leaves at the start, TCG permitting
    quiet = [t for t in from_ctrl if s0 + 0.05 < t - t0 < s1 - 0.05]
    if quiet:
        errors.append('%d frames from the controller while it was silent, at %s s' % (
            len(quiet), ', '.join('%.3f' % (t - t0) for t in quiet[:8])))
    end = statuses[1][-1][0]  # the emulator's last status: polls after it go unanswered
    heard = [t for t in polls if not (s0 - 0.05 < t - t0 < s1 + 0.05) and t < end - 0.05]
    if len(replies) < 0.97 * len(heard) or len(heard) < 100:  # (100 at ~30 Hz under TCG)
        errors.append('%d replies to %d polls outside the silence' % (len(replies), len(heard)))
    after = [t for t, _ in replies if t - t0 > s1 + 0.1]
    if not after:
        errors.append('no reply after the silence')

    # Truth (t from the emulator's start): nearest row.
    rows = list(csv.DictReader(open(a.truth)))
    tt = [float(r['t']) for r in rows]

    def truth_at(t):
        k = min(max(bisect.bisect_left(tt, t - t0), 0), len(rows) - 1)
        return {k2: float(v) for k2, v in rows[k].items()}

    worst = dict(i_q=0.0, erpm=0.0, u_d=0.0, u_q=0.0, t_motor=0.0)
    checked = 0
    for t, r in replies:
        tr = truth_at(t)
        w = tr['omega_el']
        if abs(w) < 100:  # steady state only at speed (ramps and standstill excluded)
            continue
        checked += 1
        u_d = tr['r_s'] * r['i_d'] - w * tr['l_q'] * r['i_q']
        u_q = tr['r_s'] * r['i_q'] + w * (tr['l_d'] * r['i_d'] + tr['psi_m'])
        worst['i_q'] = max(worst['i_q'], abs(r['i_q'] - tr['i_q']) / max(abs(tr['i_q']), 1.0))
        worst['erpm'] = max(worst['erpm'], abs(r['erpm'] - w * 60 / (2 * math.pi)) / abs(w * 60 / (2 * math.pi)))
        worst['u_d'] = max(worst['u_d'], abs(r['v_d'] - u_d))
        worst['u_q'] = max(worst['u_q'], abs(r['v_q'] - u_q) / abs(u_q))
        worst['t_motor'] = max(worst['t_motor'], abs(r['t_motor'] - tr['T_winding']))
    if checked < 50:
        errors.append('only %d replies at speed' % checked)
    limits = dict(i_q=0.05, erpm=0.02, u_d=0.15, u_q=0.03, t_motor=0.5)
    for k, lim in limits.items():
        if worst[k] > lim:
            errors.append('reply %s off the truth by %.4g (limit %g)' % (k, worst[k], lim))

    duration = s0 + (statuses[1][-1][0] - t0 - s1)  # time not silent
    for n, want in ((1, 50), (4, 50), (5, 50), (2, 5), (3, 5), (6, 5)):
        rate = len(statuses[n]) / duration
        if not 0.8 * want < rate < 1.2 * want:
            errors.append('status %d at %.1f Hz, configured %d Hz' % (n, rate, want))
    for t, s in statuses[4]:
        if abs(s['t_fet'] - 40.0) > 0.11:
            errors.append('STATUS_4 T_fet %.1f' % s['t_fet'])
            break
    for t, s in statuses[5]:
        if abs(s['vin'] - 48.0) > 0.5:
            errors.append('STATUS_5 V_in %.1f' % s['vin'])
            break

    print('check_vesc_capture: %d polls, %d replies (%d at speed compared with the truth), statuses %s; '
          'worst: i_q %.2f %%, ERPM %.2f %%, u_d %.3f V, u_q %.2f %%, T_motor %.2f K; silent %.3f-%.3f s, first status '
          'at %.1f ms' % (len(polls), len(replies), checked, {n: len(v) for n, v in statuses.items()},
                          100 * worst['i_q'], 100 * worst['erpm'], worst['u_d'], 100 * worst['u_q'], worst['t_motor'],
                          s0, s1, 1e3 * first_status_s))
    if errors:
        print('check_vesc_capture: FAILED\n  ' + '\n  '.join(errors[:20]))
        sys.exit(1)
    print('check_vesc_capture: passed')


if __name__ == '__main__':
    main()
