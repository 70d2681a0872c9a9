#!/bin/sh
# The VESC suite, run where vcan0 exists (inside the VM, or natively). Writes its results into $1; the
# host checks them (tests/vm/run_vesc_suite.sh).
#   1. the emulated VESC 17 (rpem sim --vesc) polled by cangen at 50 Hz — a poller that is not our code — with the
#      whole exchange captured by candump; the emulator goes silent from 6 s to 8 s
#   2. rpem record --averaged-out from native telemetry (rpem sim --can) and through a signal map
#      (config/signal-maps/rpem-native-classic.yaml over rpem replay --classic)
#   3. rpemd (source: signal_map) reading those classic frames through the map — when given its configuration
#   4. rpemd (source: signal_map) reading AX8000 TxPDOs (beckhoff-ax8000-cia402.yaml) replayed by canplayer
#      from ax8000_pdos.log (tests/vm/ax8000_pdos.py, on the host), heard by rpem listen — when given them
#   5. rpemd (source: vesc) polling the emulated VESC at 200 Hz and at 1 kHz — when rpemd has the source
out=${1:-/host}
fail=0
step() { echo "vesc_suite: $*"; }
# A recorder is ready once it says it listens (its socket is open): a fixed sleep loses the first frames
# under a loaded emulator.
wait_listening() { i=0; until grep -q "listening on" "$1" 2>/dev/null || [ $i -ge 600 ]; do sleep 0.1; i=$((i + 1)); done; }
# rpemd has estimated every sample it was sent once its status line says STALE after the sender finished (the
# loop found its queue empty for stale_timeout_s): under a loaded emulator the estimator runs slower than the
# replay and drains its queue seconds later, so a fixed sleep kills it mid-queue. $2: STALE lines before.
stale_lines() { n=$(grep -c "^rpemd STALE" "$1" 2>/dev/null); echo "${n:-0}"; }
wait_drained() { i=0; until [ "$(stale_lines "$1")" -gt "$2" ] || [ $i -ge 1200 ]; do sleep 0.1; i=$((i + 1)); done; }
echo 16777216 > /proc/sys/net/core/rmem_max 2>/dev/null

step "emulated VESC 17, polled by cangen, captured by candump"
candump -r 8388608 -L vcan0 > /tmp/vesc_capture.log &
dump=$!
rpem sim --scenario vesc-6374.yaml --vesc vcan0 --controller-id 17 --truth "$out/vesc_truth.csv" \
  --duration 12 --silent-at 6 --silent-for 2 2> "$out/vesc_emulator.txt" &
emu=$!
sleep 1
# COMM_GET_VALUES_SELECTIVE, mask 0x001801B3, reply to 0x7D: PROCESS_SHORT_BUFFER to 17, every 20 ms, 10 s
cangen vcan0 -e -I 811 -L 7 -D 7D0032001801B3 -g 20 -n 500
wait $emu || fail=1
sleep 0.2
kill $dump; wait $dump 2>/dev/null
cp /tmp/vesc_capture.log "$out/vesc_capture.log"
cat "$out/vesc_emulator.txt"

step "emulated VESC 17 -> rpem record --vesc-id 17 --poll-rate 100 --averaged-out"
rpem sim --scenario vesc-6374.yaml --vesc vcan0 --controller-id 17 --truth "$out/vesc_record_truth.csv" \
  --duration 10 2> "$out/vesc_record_emulator.txt" &
emu=$!
sleep 1
rpem record --can vcan0 --vesc-id 17 --poll-rate 100 --averaged-out "$out/vesc_avg.csv" --duration 8 \
  > "$out/vesc_avg.txt" 2>&1 || fail=1
wait $emu || fail=1
cat "$out/vesc_avg.txt"

step "native telemetry -> rpem record --averaged-out"
rpem record --can vcan0 --averaged-out "$out/native_avg.csv" --window-rate 200 --idle-timeout 1.5 > "$out/native_avg.txt" 2>&1 &
rec=$!
wait_listening "$out/native_avg.txt"
rpem sim --scenario can-stream.yaml --can vcan0 --out "$out/native_sent.csv" 2> /dev/null || fail=1
wait $rec || fail=1
cat "$out/native_avg.txt"

step "signal map over classic frames -> rpem record --averaged-out"
rpem record --can vcan0 --signal-map rpem-native-classic.yaml --averaged-out "$out/map_avg.csv" --idle-timeout 1.5 \
  > "$out/map_avg.txt" 2>&1 &
rec=$!
wait_listening "$out/map_avg.txt"
head -n 2001 "$out/native_sent.csv" > /tmp/classic_sent.csv
cp /tmp/classic_sent.csv "$out/classic_sent.csv"
rpem replay /tmp/classic_sent.csv --can vcan0 --classic --rate 1 || fail=1
wait $rec || fail=1
cat "$out/map_avg.txt"

if [ -f ./rpemd-map-vcan.yaml ]; then
  step "rpemd, source: signal_map (rpem-native-classic.yaml) <- rpem replay --classic"
  rpemd --config rpemd-map-vcan.yaml > "$out/rpemd_map.txt" 2>&1 &
  r=$!
  sleep 2
  rpem replay "$out/native_sent.csv" --can vcan0 --classic --rate 1 || fail=1
  wait_drained "$out/rpemd_map.txt" "$(stale_lines "$out/rpemd_map.txt")"
  kill -TERM $r; wait $r || fail=1
  tail -n 3 "$out/rpemd_map.txt"
fi

if [ -f ./rpemd-ax8000-vcan.yaml ] && [ -f "$out/ax8000_pdos.log" ]; then
  step "rpemd, source: signal_map (beckhoff-ax8000-cia402.yaml) <- canplayer, AX8000 TxPDOs"
  rm -rf /tmp/rpemd-ax8000
  cp "$out/ax8000_pdos.log" /tmp/ax8000_pdos.log
  rpemd --config rpemd-ax8000-vcan.yaml > "$out/ax8000_rpemd.txt" 2>&1 &
  r=$!
  rpem listen --prefix AX8000_ --diagnostics --csv "$out/ax8000_est.csv" > "$out/ax8000_listen.txt" 2>&1 &
  l=$!
  sleep 2
  canplayer -I /tmp/ax8000_pdos.log vcan0=vcan0 || fail=1
  wait_drained "$out/ax8000_rpemd.txt" "$(stale_lines "$out/ax8000_rpemd.txt")"
  sleep 1   # the last estimates reach rpem listen
  kill -TERM $r; wait $r || fail=1
  kill -INT $l; wait $l
  tail -n 2 "$out/ax8000_rpemd.txt"
  grep 'signal_map:' "$out/ax8000_listen.txt" | tail -n 1
fi

if [ -f ./vesc_rpemd.sh ]; then
  step "rpemd, source: vesc"
  sh ./vesc_rpemd.sh "$out" || fail=1
else
  step "rpemd has no 'source: vesc' in this build: skipped (reported by the host side)"
  echo skipped > "$out/rpemd_vesc_skipped"
fi
exit $fail
