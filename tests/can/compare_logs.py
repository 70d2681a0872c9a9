#!/usr/bin/env python3
"""Compares two drive logs sample by sample: the same times (to the microsecond) and every value within
half the telemetry resolution (can/rpem_telemetry.dbc). Used for the sim → vcan → record round trip.

The temperature frame (RPEM_TEMPERATURES, every 100 ms of drive time) goes with the sample received after it:
each reading in the received log (T_winding, T_coolant; `nan` on the rows between) must be within half its step
of the sent log's value at one of the three samples either side (CAN FD holds three samples for a frame, classic
sends it after its sample's frames); a column the sent log lacks (or leaves nan) has no reading. With
--temperatures a sent column must arrive every 100 ms: one reading per 100 ms of samples, the last frame possibly
with no sample after it to go with.

    compare_logs.py SENT.csv RECEIVED.csv [--fd-udc] [--temperatures]
"""
import csv
import math
import sys

HALF = {"i_a": 0.0005, "i_b": 0.0005, "i_c": 0.0005, "u_a": 0.01, "u_b": 0.01, "u_c": 0.01,
        "theta_el": math.pi / 65536, "omega_el": 0.025, "u_dc": 0.01}


def main(argv):
    sent = list(csv.DictReader(open(argv[1])))
    received = list(csv.DictReader(open(argv[2])))
    fd_udc = "--fd-udc" in argv  # CAN FD carries one u_dc per frame (that of its first sample)
    if len(sent) != len(received):
        print(f"compare_logs: {len(sent)} samples sent, {len(received)} received")
        return 1
    for k, (s, r) in enumerate(zip(sent, received)):
        if round(float(s["t"]) * 1e6) != round(float(r["t"]) * 1e6):
            print(f"compare_logs: sample {k}: t {s['t']} sent, {r['t']} received")
            return 1
        for key, tol in HALF.items():
            if key == "u_dc" and fd_udc:
                continue
            d = float(r[key]) - float(s[key])
            if key == "theta_el":
                d = math.remainder(d, 2 * math.pi)
            if abs(d) > tol * (1 + 1e-9) + 1e-12:
                print(f"compare_logs: sample {k}: {key} {s[key]} sent, {r[key]} received")
                return 1
    if not compare_temperatures(sent, received, "--temperatures" in argv):
        return 1
    print(f"compare_logs: {len(sent)} samples agree within half a resolution step")
    return 0


def finite(row, column):
    v = row.get(column)
    return v not in (None, "") and math.isfinite(float(v))


def compare_temperatures(sent, received, required):
    half = 0.05  # RPEM_TEMPERATURES: 0.1 °C per bit
    for column in ("T_winding", "T_coolant"):
        readings = [k for k, r in enumerate(received) if finite(r, column)]
        sent_has = any(finite(r, column) for r in sent)
        if not sent_has:
            if readings:
                print(f"compare_logs: {column} {received[readings[0]][column]} received at sample {readings[0]}, "
                      "none sent")
                return False
            continue
        for k in readings:
            near = [float(sent[j][column]) for j in range(max(0, k - 3), min(len(sent), k + 4)) if finite(sent[j], column)]
            got = float(received[k][column])
            if not near or min(abs(got - v) for v in near) > half * (1 + 1e-9) + 1e-12:
                print(f"compare_logs: {column} {got} received at sample {k}; sent around it: {near}")
                return False
        span = float(sent[-1]["t"]) - float(sent[0]["t"])
        frames = int(span / 0.1 + 1e-9) + 1
        if required and not frames - 1 <= len(readings) <= frames:
            print(f"compare_logs: {len(readings)} {column} readings over {span} s of samples (one every 100 ms: "
                  f"{frames - 1} or {frames})")
            return False
        if readings:
            print(f"compare_logs: {len(readings)} {column} readings agree within half a resolution step")
    return True


if __name__ == "__main__":
    sys.exit(main(sys.argv))
