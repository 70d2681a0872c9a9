#!/bin/sh
# rpemd end to end, where vcan0 exists (the PREEMPT_RT VM): the simulated drive streams over vcan0,
# rpemd estimates, `rpem listen` records the LCM estimates and diagnostics. Results go to $1; the host
# checks them (tests/vm/check_daemon_suite.py).
out=${1:-/host}
cfg=rpemd-vcan.yaml
rate=0.4  # the emulated VM cannot run drive, daemon and listener at 8 kHz in real time
step() { echo "daemon_suite: $*"; }
start_rpemd() { rpemd --config $cfg > "$out/$1_rpemd.txt" 2>&1 & echo $! > /tmp/rpemd.pid; }
stop_rpemd() { kill -TERM "$(cat /tmp/rpemd.pid)"; wait "$(cat /tmp/rpemd.pid)" 2>/dev/null; }

run_steps() {  # name, extra rpem sim options
  name=$1; shift
  step "$name: -8 % steps of R_s and psi_m, sim options: $*"
  rm -rf /tmp/rpemd
  start_rpemd "$name"
  rpem listen --csv "$out/${name}_est.csv" --diagnostics > "$out/${name}_listen.txt" 2>&1 &
  listen=$!
  sleep 2
  rpem sim --scenario e2e-steps.yaml --can vcan0 --rate $rate --truth "$out/${name}_truth.csv" "$@" 2> "$out/${name}_sim.txt"
  sleep 2
  stop_rpemd
  kill -INT $listen; wait $listen
}

run_steps steps
run_steps loss_random --drop-probability 0.1 --drop-seed 3
run_steps loss_burst --drop-probability 0.1 --drop-burst 12 --drop-seed 4

step "faults: vcan0 down/up, blocked LCM, malformed frames and commands, SIGKILL and restart"
rm -rf /tmp/rpemd
start_rpemd faults
rpem listen --diagnostics --csv "$out/faults_est.csv" > "$out/faults_listen.txt" 2>&1 &
listen=$!
sleep 1
rpem sim --scenario e2e-steady.yaml --can vcan0 --rate $rate 2> "$out/faults_sim.txt" &
sim=$!
sleep 10
echo "$(date +%s) vcan0 down" >> "$out/faults_events.txt"; ip link set vcan0 down
sleep 2
echo "$(date +%s) vcan0 up" >> "$out/faults_events.txt"; ip link set vcan0 up
sleep 4
echo "$(date +%s) lcm blocked" >> "$out/faults_events.txt"; ip route del 224.0.0.0/4 dev lo
sleep 4
ip route add 224.0.0.0/4 dev lo; echo "$(date +%s) lcm restored" >> "$out/faults_events.txt"
sleep 2
echo "$(date +%s) malformed" >> "$out/faults_events.txt"
cansend vcan0 100##1.00112233                       # CAN FD frame of the wrong length
cansend vcan0 100##1$(printf '%0128d' 7)             # right length, garbage: CRC mismatch
cansend vcan0 110#0011223344                         # classic frame of the wrong length
rpem command --malformed
rpem command freeze --seq 5
rpem command unfreeze --seq 5                        # an old sequence number: rejected
rpem command unfreeze --seq 6
sleep 2
echo "$(date +%s) sigkill" >> "$out/faults_events.txt"
kill -KILL "$(cat /tmp/rpemd.pid)"
sleep 1
start_rpemd restarted
sleep 4
stop_rpemd
kill $sim 2>/dev/null; wait $sim 2>/dev/null
kill -INT $listen; wait $listen
cp /tmp/rpemd/estimates.json "$out/restarted_state.json" 2>/dev/null
step "done"
