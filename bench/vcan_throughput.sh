#!/usr/bin/env bash
# Sustained telemetry through vcan0 in the PREEMPT_RT VM:
#  1. `rpem sim --can vcan0` streams the drive at 8 kHz (CAN FD, 3 samples per frame) in real time for
#     SECONDS, `rpem record --latency` receives it: losses, kernel drops, and the latency from each
#     frame's scheduled time to its kernel receive timestamp (sender lateness + transport);
#  2. bench/vcan_latency: the transport alone, write(2) → kernel receive timestamp → recvmsg(2).
#   vcan_throughput.sh BUILD_DIR [SECONDS]
set -euo pipefail
build=$(cd "$1" && pwd)
seconds=${2:-60}
repo=$(cd "$(dirname "$0")/.." && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cat >"$out/stream.yaml" <<YAML
name: vcan-throughput
machine: builtin:paper-ipmsm
duration_s: $seconds
inverter: {model: averaged}
sensors: {current_noise_A: 0.02, current_lsb_A: 0.01, encoder_counts: 16384}
initial: {speed_rpm: 300, torque_Nm: 13.04, u_dc_V: 220}
YAML
"$repo/tests/vm/vm_rig.sh" run --timeout $((seconds * 3 + 300)) --share "$out" --file "$build/tools/rpem" \
  --file "$out/stream.yaml" --file "$build/bench/vcan_latency" -- "
    rpem record --can vcan0 --out /tmp/rec.csv --idle-timeout 2 --latency 2> /host/record.txt &
    sleep 1
    rpem sim --scenario stream.yaml --can vcan0 --wall-timestamps 2> /host/sim.txt
    wait
    cat /host/sim.txt /host/record.txt
    vcan_latency vcan0 2667 $seconds
    grep -q 'lost 0, duplicated 0, reordered 0' /host/record.txt && grep -q 'kernel drops 0,' /host/record.txt"
