#!/usr/bin/env bash
# ctest entry (label cli): the temperature frame read back by the DBC alone. The simulated drive's half second
# with its temperatures logged (can-temperatures.yaml) streamed as a candump -L capture on CAN FD and classic
# CAN, each decoded by tests/can/dbc_decode.py (a generic DBC reader, no project code) against the drive log sent.
#   run_dbc_temperatures.sh BUILD_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$build/tools/rpem" sim --scenario "$here/can-temperatures.yaml" --out "$out/sent.csv" --candump "$out/fd.log" --rate 0
"$build/tools/rpem" replay "$out/sent.csv" --candump "$out/classic.log" --classic --rate 0
grep -q "T_winding" <(head -1 "$out/sent.csv") || { echo "run_dbc_temperatures: the log has no T_winding" >&2; exit 1; }
python3 "$here/dbc_decode.py" "$repo/can/rpem_telemetry.dbc" "$out/fd.log" "$out/sent.csv" --fd
python3 "$here/dbc_decode.py" "$repo/can/rpem_telemetry.dbc" "$out/classic.log" "$out/sent.csv" --classic
