#!/usr/bin/env bash
# ctest entry `vesc_suite` (label vcan): tests/vm/vesc_suite.sh natively where the host has vcan, else in the
# PREEMPT_RT VM, then checks its outputs on the host (tests/can/check_vesc_capture.py,
# tests/can/check_averaged_record.py).
#   run_vesc_suite.sh BUILD_DIR [--rpemd]     (--rpemd: also rpemd's parts: source: signal_map with the AX8000
#                                             map, tests/vm/check_ax8000_rpemd.py, and source: vesc,
#                                             tests/vm/vesc_rpemd.sh)
set -euo pipefail
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
# RPEM_VESC_SUITE_OUT=DIR keeps the outputs there (debugging); otherwise a temporary directory.
if [[ -n ${RPEM_VESC_SUITE_OUT:-} ]]; then
  out=$RPEM_VESC_SUITE_OUT
  mkdir -p "$out"
else
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
fi
cp "$repo/scenarios/can-stream.yaml" "$repo/scenarios/vesc-6374.yaml" "$repo/scenarios/vesc-tool-hall.yaml" \
   "$repo/config/vesc-6374-outrunner.yaml" "$repo/config/signal-maps/rpem-native-classic.yaml" "$out/"
# The scenarios name their machine relative to themselves (../config/…): give them that layout.
mkdir -p "$out/config" && cp "$repo/config/vesc-6374-outrunner.yaml" "$out/config/"
sed -i 's|^machine: ../config/|machine: config/|' "$out/vesc-6374.yaml" "$out/vesc-tool-hall.yaml"

# rpemd's part runs where the tree has `source: vesc` (daemon/src/vesc_source.cpp, branch vesc-12).
rpemd_files=()
if [[ ${2:-} == --rpemd && -f $repo/daemon/src/vesc_source.cpp && -x $build/daemon/rpemd ]]; then
  cp "$here/vesc_rpemd.sh" "$here/rpemd-vesc-vcan.yaml" "$here/rpemd-map-vcan.yaml" "$out/"
  rpemd_files=(--file "$build/daemon/rpemd" --file "$here/vesc_rpemd.sh" --file "$here/rpemd-vesc-vcan.yaml"
               --file "$here/rpemd-map-vcan.yaml" --file "$repo/config/vesc-6374-outrunner.yaml"
               --file "$out/vesc-tool-hall.yaml")
  # The AX8000 part: its drive simulated and its TxPDOs built here (the VM has no python), replayed there.
  echo "run_vesc_suite: simulating the AX8000 drive (tests/vm/ax8000-vcan.yaml) and building its TxPDOs"
  "$build/tools/rpem" sim --scenario "$here/ax8000-vcan.yaml" --out "$out/ax8000_drive.csv" \
    --truth "$out/ax8000_truth.csv" 2> /dev/null
  python3 "$here/ax8000_pdos.py" "$out/ax8000_drive.csv" "$out/ax8000_pdos.log" --expect "$out/ax8000_pdos.json"
  cp "$here/rpemd-ax8000-vcan.yaml" "$repo/config/beckhoff-am8141.yaml" \
     "$repo/config/signal-maps/beckhoff-ax8000-cia402.yaml" "$out/"
  rpemd_files+=(--file "$here/rpemd-ax8000-vcan.yaml" --file "$repo/config/beckhoff-am8141.yaml"
                --file "$repo/config/signal-maps/beckhoff-ax8000-cia402.yaml")
fi

if "$here/vm_rig.sh" native-vcan; then
  echo "run_vesc_suite: native vcan0"
  (cd "$out" && PATH="$build/tools:$build/daemon:$PATH" sh "$here/vesc_suite.sh" "$out")
else
  echo "run_vesc_suite: no vcan on this host; running in the PREEMPT_RT VM"
  "$here/vm_rig.sh" run --timeout 900 --share "$out" \
    --file "$build/tools/rpem" --file "$here/vesc_suite.sh" \
    --file "$out/vesc-6374.yaml" --file "$out/config/vesc-6374-outrunner.yaml:/work/config/vesc-6374-outrunner.yaml" \
    --file "$repo/scenarios/can-stream.yaml" --file "$repo/config/signal-maps/rpem-native-classic.yaml" \
    "${rpemd_files[@]}" -- 'sh /work/vesc_suite.sh /host'
fi

echo "run_vesc_suite: checking the outputs on the host"
python3 "$repo/tests/can/check_vesc_capture.py" "$out/vesc_capture.log" "$out/vesc_truth.csv" \
  "$out/vesc_emulator.txt" --controller 17 \
  --poller 0x7D --silent 6 8 --record "$out/vesc_avg.csv" "$out/vesc_record_truth.csv" --record-rate 100
python3 "$repo/tests/can/check_averaged_record.py" "$out/native_sent.csv" "$out/native_avg.csv" --rate 200
python3 "$repo/tests/can/check_averaged_record.py" "$out/classic_sent.csv" "$out/map_avg.csv"
if [[ -f $out/rpemd_vesc_skipped ]]; then
  echo "run_vesc_suite: rpemd's 'source: vesc' not in this build — its part did not run"
else
  "$build/tools/rpem" estimate --log "$out/native_sent.csv" --out "$out/map_offline_est.csv" > /dev/null
  python3 "$here/check_map_rpemd.py" "$out/rpemd_map.txt" "$out/map_offline_est.csv"
  python3 "$here/check_ax8000_rpemd.py" "$out"
  for run in r200 r1k; do python3 "$here/check_vesc_rpemd.py" "$out" "$run"; done
  python3 "$here/check_vesc_rpemd.py" "$out" r10 --prompt-replies
  python3 "$here/check_vesc_hall_rpemd.py" "$out"
fi
echo "run_vesc_suite: passed"
