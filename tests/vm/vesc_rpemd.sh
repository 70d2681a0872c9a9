#!/bin/sh
# rpemd (source: vesc) against the emulated VESC 17 over vcan0, at 200 Hz and at 1 kHz: 70 s each, the
# emulator silent from 45 s to 48 s, a second poller (cangen, host id 0xC8) stealing averages at
# 20 Hz from 55 s to 60 s. Outputs in $1; tests/vm/check_vesc_rpemd.py checks them on the host.
out=${1:-/host}
fail=0
run() {  # name poll-rate reply-timeout
  name=$1
  sed -e "s/poll_rate_Hz: .*/poll_rate_Hz: $2/" -e "s/reply_timeout_s: [0-9.e-]*/reply_timeout_s: $3/" \
    rpemd-vesc-vcan.yaml > "/tmp/$name.yaml"
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
  tail -n 3 "$out/${name}_emulator.txt"
}
run r200 200 0.005
run r1k 1000 0.001
exit $fail
