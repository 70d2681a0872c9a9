#!/bin/sh
# rpemd (source: vesc) against the emulated VESC 17 over vcan0, at 200 Hz, 1 kHz and 10 Hz: 70 s each, the
# emulator silent from 45 s to 48 s, a second poller (cangen, host id 0xC8) stealing averages at
# 20 Hz from 55 s to 60 s; then 30 s of a Hall drive crawling. Outputs in $1; tests/vm/check_vesc_rpemd.py and
# check_vesc_hall_rpemd.py check them on the host.
out=${1:-/host}
fail=0
run() {  # name poll-rate reply-timeout [default-stale: stale_timeout_s left out]
  name=$1
  sed -e "s/poll_rate_Hz: .*/poll_rate_Hz: $2/" -e "s/reply_timeout_s: [0-9.e-]*/reply_timeout_s: $3/" \
    rpemd-vesc-vcan.yaml > "/tmp/$name.yaml"
  [ "${4:-}" = default-stale ] && sed -i "/stale_timeout_s/d" "/tmp/$name.yaml"
  cp "/tmp/$name.yaml" "$out/${name}_config.yaml"   # the configuration rpemd ran, for the checks
  cp vesc-6374-outrunner.yaml /tmp/
  rm -rf /tmp/rpemd-vesc
  rpem sim --scenario vesc-6374.yaml --vesc vcan0 --controller-id 17 --truth "$out/${name}_truth.csv" \
    --duration 70 --silent-at 45 --silent-for 3 2> "$out/${name}_emulator.txt" &
  emu=$!
  rpemd --config "/tmp/$name.yaml" > "$out/${name}_rpemd.txt" 2>&1 &
  daemon=$!
  rpem listen --prefix VESC17_ --diagnostics --csv "$out/${name}_est.csv" > "$out/${name}_listen.txt" 2>&1 &
  listen=$!
  sleep 55
  cangen vcan0 -e -I 811 -L 7 -D C80032001801B3 -g 50 -n 100   # the thief: host id 0xC8, 20 Hz, 5 s
  wait $emu || fail=1
  sleep 1
  kill -TERM $daemon; wait $daemon || fail=1
  kill -INT $listen; wait $listen
  tail -n 4 "$out/${name}_emulator.txt"
}
run r200 200 0.005
run r1k 1000 0.001
# A slow poll, its timeout the whole period, the stale timeout rpemd's default for it: the replies are prompt and
# the estimates go stale only in the silence (check_vesc_rpemd.py --prompt-replies).
run r10 10 0.1 default-stale
# A Hall drive crawling (vesc-tool-hall.yaml, its first 30 s: standstill under load, 5, 15, 30 rpm) with the machine
# file saying `hall`: rpemd asks for the tachometer and counts each window's speed (docs/rpemd.md, "A Hall drive at
# a crawl"); tests/vm/check_vesc_hall_rpemd.py checks it.
sed -e "s/machine_config: .*/machine_config: vesc-6374-hall.yaml/" rpemd-vesc-vcan.yaml > /tmp/hall.yaml
sed -e "s/angle_source: sensorless/angle_source: hall/" vesc-6374-outrunner.yaml > /tmp/vesc-6374-hall.yaml
rm -rf /tmp/rpemd-vesc
rpem sim --scenario vesc-tool-hall.yaml --vesc vcan0 --controller-id 17 --truth "$out/hall_truth.csv" \
  --duration 30 2> "$out/hall_emulator.txt" &
emu=$!
rpemd --config /tmp/hall.yaml > "$out/hall_rpemd.txt" 2>&1 &
daemon=$!
rpem listen --prefix VESC17_ --diagnostics --csv "$out/hall_est.csv" > "$out/hall_listen.txt" 2>&1 &
listen=$!
wait $emu || fail=1
sleep 1
kill -TERM $daemon; wait $daemon || fail=1
kill -INT $listen; wait $listen
tail -n 4 "$out/hall_emulator.txt"
exit $fail
