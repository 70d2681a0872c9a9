#!/usr/bin/env bash
# ctest entry of the `vcan` label: runs tests/vm/vcan_suite.sh natively where the host kernel has vcan,
# otherwise inside the PREEMPT_RT VM (tests/vm/vm_rig.sh), then checks its outputs on the host:
# recorded = sent within the resolution, the candump capture decodes with the DBC, canplayer's replay
# and the classic mapping round-trip too. Then the bus bring-up units' commands under the units' own
# credentials (tests/vm/bus_units.sh; in the VM also on an emulated CAN controller).
#   run_vcan_suite.sh BUILD_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cp "$repo/scenarios/can-stream.yaml" "$repo/tests/can/can-temperatures.yaml" "$out/"

if "$here/vm_rig.sh" native-vcan; then
  echo "run_vcan_suite: native vcan0"
  (cd "$out" && PATH="$build/tools:$build/tests/can:$PATH" sh "$here/vcan_suite.sh" "$out")
  sh "$here/bus_units.sh" "$repo/systemd" | tee "$out/bus_units.txt"
else
  echo "run_vcan_suite: no vcan on this host; running in the PREEMPT_RT VM"
  "$here/vm_rig.sh" run --timeout 900 --share "$out" --can-controller \
    --file "$build/tools/rpem" --file "$build/tests/can/test_socketcan" \
    --file "$here/vcan_suite.sh" --file "$repo/scenarios/can-stream.yaml" --file "$here/../can/can-temperatures.yaml" \
    --file "$here/bus_units.sh" --file "$(command -v setpriv)" \
    --file "$repo/systemd/rpem-can@.service" --file "$repo/systemd/rpem-vcan@.service" \
    -- 'sh /work/vcan_suite.sh /host; rc=$?; sh /work/bus_units.sh /work > /host/bus_units.txt 2>&1; bu=$?; cat /host/bus_units.txt; exit $((rc | bu))'
fi

echo "run_vcan_suite: checking the outputs on the host"
python3 "$repo/tests/can/compare_logs.py" "$out/sent.csv" "$out/recorded.csv" --fd-udc
python3 "$repo/tests/can/dbc_decode.py" "$repo/can/rpem_telemetry.dbc" "$out/capture.log" "$out/sent.csv"
python3 "$repo/tests/can/compare_logs.py" "$out/sent.csv" "$out/replayed.csv" --fd-udc
python3 "$repo/tests/can/compare_logs.py" "$out/classic_sent.csv" "$out/classic_recorded.csv"
python3 "$repo/tests/can/compare_logs.py" "$out/temps_sent.csv" "$out/temps_recorded.csv" --fd-udc --temperatures
python3 "$repo/tests/can/check_averaged_record.py" "$out/temps_sent.csv" "$out/temps_avg.csv" --rate 200 --temperatures
for f in record.txt record2.txt record3.txt record4.txt; do
  if ! grep -q "gaps 1, lost 0, duplicated 0, reordered 0, crc 0" "$out/$f"; then
    echo "run_vcan_suite: $f reports losses:"; cat "$out/$f"; exit 1
  fi
  grep -q "kernel drops 0," "$out/$f" || { echo "run_vcan_suite: kernel drops in $f"; cat "$out/$f"; exit 1; }
done
grep -q "^bus_units: passed" "$out/bus_units.txt" || { echo "run_vcan_suite: the bus units' commands failed"; exit 1; }
echo "run_vcan_suite: passed"
