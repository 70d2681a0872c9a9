#!/bin/sh
# The vcan suite, run where vcan0 exists (inside the VM, or natively). Writes its results into $1.
#   1. SocketCAN unit tests on vcan0 (test_socketcan)
#   2. sim → vcan0 → record: the simulated drive streamed in real time and recorded back
#   3. the same traffic captured with candump -L (checked against the DBC on the host)
#   4. canplayer replays that capture into rpem record
#   5. classic-CAN mapping through vcan0
#   6. a drive sending its temperature frame (can-temperatures.yaml), recorded as phase samples and as windows
out=${1:-/host}
fail=0
step() { echo "vcan_suite: $*"; }
# A recorder is ready once it says it listens (its socket is open): a fixed sleep loses the first frames
# under a loaded emulator.
wait_listening() { i=0; until grep -q "listening on" "$1" 2>/dev/null || [ $i -ge 600 ]; do sleep 0.1; i=$((i + 1)); done; }

step "SocketCAN tests"
test_socketcan --gtest_color=no || fail=1

step "sim -> vcan0 -> record (CAN FD), captured by candump"
# Under emulation candump is scheduled late: it gets a large socket buffer (-r, as rpem record has; the
# limit raised first) and writes its capture to RAM — each line to the 9p-shared host directory would be
# slow enough to overflow any buffer — and the capture is copied out afterwards.
echo 16777216 > /proc/sys/net/core/rmem_max 2>/dev/null
candump -r 8388608 -L vcan0,100:7FF > /tmp/capture.log &
dump=$!
rpem record --can vcan0 --out "$out/recorded.csv" --idle-timeout 1.5 > "$out/record.txt" 2>&1 &
rec=$!
wait_listening "$out/record.txt"
rpem sim --scenario can-stream.yaml --can vcan0 --out "$out/sent.csv" 2> "$out/sim.txt" || fail=1
wait $rec || fail=1
kill $dump; wait $dump 2>/dev/null
cp /tmp/capture.log "$out/capture.log"
cat "$out/record.txt"

step "canplayer -> record"
rpem record --can vcan0 --out "$out/replayed.csv" --idle-timeout 1.5 > "$out/record2.txt" 2>&1 &
rec=$!
wait_listening "$out/record2.txt"
canplayer -I /tmp/capture.log vcan0=vcan0 || fail=1
wait $rec || fail=1
cat "$out/record2.txt"

step "replay -> record (classic CAN)"
rpem record --can vcan0 --out "$out/classic_recorded.csv" --idle-timeout 1.5 > "$out/record3.txt" 2>&1 &
rec=$!
wait_listening "$out/record3.txt"
head -n 2001 "$out/sent.csv" > "$out/classic_sent.csv"
rpem replay "$out/classic_sent.csv" --can vcan0 --classic --rate 4 || fail=1
wait $rec || fail=1
cat "$out/record3.txt"

step "sim with temperatures -> record --out and --averaged-out (CAN FD)"
rpem record --can vcan0 --out "$out/temps_recorded.csv" --idle-timeout 1.5 > "$out/record4.txt" 2>&1 &
rec=$!
rpem record --can vcan0 --averaged-out "$out/temps_avg.csv" --window-rate 200 --idle-timeout 1.5 \
  > "$out/record5.txt" 2>&1 &
rec_avg=$!
wait_listening "$out/record4.txt"
wait_listening "$out/record5.txt"
rpem sim --scenario can-temperatures.yaml --can vcan0 --out "$out/temps_sent.csv" 2> "$out/sim_temps.txt" || fail=1
wait $rec || fail=1
wait $rec_avg || fail=1
cat "$out/record4.txt" "$out/record5.txt"
exit $fail
