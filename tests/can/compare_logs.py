#!/usr/bin/env python3
"""Compares two drive logs sample by sample: the same times (to the microsecond) and every value within
half the telemetry resolution (can/rpem_telemetry.dbc). Used for the sim → vcan → record round trip.

    compare_logs.py SENT.csv RECEIVED.csv [--fd-udc]
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
    print(f"compare_logs: {len(sent)} samples agree within half a resolution step")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
