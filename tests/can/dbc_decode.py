#!/usr/bin/env python3
"""Independent check of the telemetry protocol: decodes a `candump -L` log with the DBC file alone (a
generic little-endian DBC reader, no project code) and compares the samples with a drive-log CSV.

    dbc_decode.py DBC CANDUMP.log DRIVE_LOG.csv [--fd|--classic]

Exit 0 when every sample of the log is found in the capture, in order, within half a resolution step
of every signal (the DBC factor), and, where the log has T_winding or T_coolant, when the capture's
temperature messages (RPEM_TEMPERATURES) come every 100 ms of drive time, each within half a step of the log's
value at the samples around it (the DBC's comment: the readings go with the next sample); 1 with the first
difference otherwise.
"""
import csv
import math
import re
import sys


def parse_dbc(path):
    messages = {}
    current = None
    for line in open(path):
        m = re.match(r"BO_ (\d+) (\w+): (\d+) (\w+)", line)
        if m:
            current = {"name": m.group(2), "dlc": int(m.group(3)), "signals": {}}
            messages[int(m.group(1))] = current
            continue
        m = re.match(r'\s+SG_ (\w+) : (\d+)\|(\d+)@([01])([+-]) \(([^,]+),([^)]+)\) \[([^|]+)\|([^\]]+)\] "([^"]*)"', line)
        if m and current is not None:
            if m.group(4) != "1":
                raise SystemExit("only little-endian (Intel) signals are expected")
            current["signals"][m.group(1)] = {
                "start": int(m.group(2)), "length": int(m.group(3)), "signed": m.group(5) == "-",
                "factor": float(m.group(6)), "offset": float(m.group(7))}
    return messages


def decode(message, data):
    raw_all = int.from_bytes(data, "little")
    out = {}
    for name, s in message["signals"].items():
        raw = (raw_all >> s["start"]) & ((1 << s["length"]) - 1)
        if s["signed"] and raw >> (s["length"] - 1):
            raw -= 1 << s["length"]
        out[name] = raw * s["factor"] + s["offset"]
        out[name + ".raw"] = raw
    return out


TEMPERATURES = 0x118


def read_capture(path, messages):
    """The samples, and the temperature messages as (index of the next sample, decoded signals)."""
    samples = []
    temperatures = []
    classic = {}
    for line in open(path):
        m = re.match(r"\((\d+\.\d+)\) (\S+) ([0-9A-Fa-f]+)(##[0-9A-Fa-f]|#)([0-9A-Fa-f]*)", line.strip())
        if not m:
            continue
        can_id = int(m.group(3), 16)
        data = bytes.fromhex(m.group(5))
        if can_id not in messages:
            continue
        d = decode(messages[can_id], data)
        if can_id == TEMPERATURES:
            temperatures.append((len(samples), d))
        elif can_id == 0x100:
            for j in range(int(d["NSamples"])):
                samples.append({
                    "t": d["T_first"] + j * d["Period"], "u_dc": d["U_dc"],
                    **{k: d[f"S{j}_{k}"] for k in ("i_a", "i_b", "i_c", "u_a", "u_b", "u_c", "theta_el", "omega_el")}})
        else:
            counter = d["E2E_Counter"]
            classic.setdefault(counter, {}).update(d)
            if can_id == 0x114:
                c = classic.pop(counter)
                samples.append({"t": c["T_low"], "u_dc": c["U_dc"],
                                **{k: c[k] for k in ("i_a", "i_b", "i_c", "u_a", "u_b", "u_c", "theta_el", "omega_el")}})
    return samples, temperatures


def check_temperatures(temperatures, rows, messages):
    """Each message's readings near the log's at the samples around the one they go with; one every 100 ms."""
    signals = messages[TEMPERATURES]["signals"]
    period = float(rows[1]["t"]) - float(rows[0]["t"]) if len(rows) > 1 else 0.0
    checked = 0
    for column in ("T_winding", "T_coolant"):
        half = signals[column]["factor"] / 2
        if column not in rows[0]:
            bad = [d for _, d in temperatures if d[column + ".raw"] != -32768]
            if bad:
                print(f"dbc_decode: {column} in the capture ({bad[0][column]}), none in the log")
                return False
            continue
        times = []
        for at, d in temperatures:
            if d[column + ".raw"] == -32768:
                continue
            # FD holds up to three samples for a frame: the sender is within three of the next sample.
            near = [float(rows[k][column]) for k in range(max(0, at - 3), min(len(rows), at + 4))]
            if not near or min(abs(d[column] - v) for v in near) > half * (1 + 1e-9) + 1e-12:
                print(f"dbc_decode: {column} = {d[column]} before sample {at}; the log has {near} around it")
                return False
            times.append(float(rows[min(at, len(rows) - 1)]["t"]))
            checked += 1
        span = float(rows[-1]["t"]) - float(rows[0]["t"])
        if len(times) != int(span / 0.1 + 1e-9) + 1:
            print(f"dbc_decode: {len(times)} {column} readings over {span} s of samples (every 100 ms: "
                  f"{int(span / 0.1 + 1e-9) + 1})")
            return False
        for a, b in zip(times, times[1:]):
            if abs((b - a) - 0.1) > 4 * period + 1e-9:
                print(f"dbc_decode: {column} readings {b - a} s apart (100 ms)")
                return False
    if checked:
        print(f"dbc_decode: {checked} temperature readings agree within half a resolution step")
    return True


def main(argv):
    if len(argv) < 4:
        print(__doc__)
        return 2
    messages = parse_dbc(argv[1])
    fd = "--classic" not in argv
    captured, temperatures = read_capture(argv[2], messages)
    rows = list(csv.DictReader(open(argv[3])))
    if len(captured) != len(rows):
        print(f"dbc_decode: {len(captured)} samples in the capture, {len(rows)} in the log")
        return 1
    sig = messages[0x100]["signals"] if fd else {**messages[0x110]["signals"], **messages[0x111]["signals"],
                                                 **messages[0x112]["signals"], **messages[0x113]["signals"]}
    half = {k: messages[0x100]["signals"]["S0_" + k]["factor"] / 2 for k in
            ("i_a", "i_b", "i_c", "u_a", "u_b", "u_c", "theta_el", "omega_el")}
    half["u_dc"] = messages[0x100]["signals"]["U_dc"]["factor"] / 2
    time_span = 2 ** 32 if fd else 2 ** 24
    for k, (c, r) in enumerate(zip(captured, rows)):
        t_us = round(float(r["t"]) * 1e6) % time_span
        if abs(round(c["t"] * 1e6) - t_us) > 0:
            print(f"dbc_decode: sample {k}: time {c['t']} s in the capture, {float(r['t'])} s in the log")
            return 1
        for key, tol in half.items():
            if key == "u_dc" and fd:
                continue  # one u_dc per FD frame (that of its first sample)
            expected = float(r[key])
            got = c[key]
            if key == "theta_el":
                diff = math.remainder(got - expected, 2 * math.pi)
            else:
                diff = got - expected
            if abs(diff) > tol * (1 + 1e-9) + 1e-12:
                print(f"dbc_decode: sample {k}: {key} = {got} in the capture, {expected} in the log (tolerance {tol})")
                return 1
    print(f"dbc_decode: {len(rows)} samples agree within half a resolution step ({'CAN FD' if fd else 'classic'})")
    return 0 if check_temperatures(temperatures, rows, messages) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
