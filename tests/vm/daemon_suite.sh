#!/bin/sh
# rpemd end to end, where vcan0 exists (the PREEMPT_RT VM): the simulated drive streams over vcan0,
# rpemd estimates, `rpem listen` records the LCM estimates and diagnostics. Results go to $1; the host
# checks them (tests/vm/check_daemon_suite.py).
out=${1:-/host}
cfg=rpemd-vcan.yaml
rate=0.4  # the emulated VM cannot run drive, daemon and listener at 8 kHz in real time
step() { echo "daemon_suite: $*"; }
# Keys (docs/rpemd.md, "Authentication"): rpemd reads them from $CREDENTIALS_DIRECTORY as systemd's
# LoadCredential= hands them over; the supervisor holds the command key and the publish key, the
# attacker only keys of its own (one under the command key's id, one under the publish key's).
keys=/tmp/keys
rm -rf $keys; mkdir -p -m 700 $keys/credentials $keys/attacker
rpem keygen --id 1 --out $keys/credentials/command.key
rpem keygen --id 2 --out $keys/credentials/publish.key
rpem keygen --id 1 --out $keys/attacker/guess.key
rpem keygen --id 2 --out $keys/attacker/publish.key
export CREDENTIALS_DIRECTORY=$keys/credentials
cmd="rpem command --key $keys/credentials/command.key"
listen_keyed="rpem listen --key $keys/credentials/publish.key"
start_rpemd() { rpemd --config "${2:-$cfg}" > "$out/$1_rpemd.txt" 2>&1 & echo $! > /tmp/rpemd.pid; }
# A run with the drive streaming the steady scenario and `rpem listen` recording: start_streaming NAME [CONFIG]
start_streaming() {
  start_rpemd "$1" "$2"
  $listen_keyed --diagnostics --csv "$out/$1_est.csv" > "$out/$1_listen.txt" 2>&1 &
  listen=$!
  sleep 1
  rpem sim --scenario e2e-steady.yaml --can vcan0 --rate $rate 2> "$out/$1_sim.txt" &
  sim=$!
}
stop_rpemd() { kill -TERM "$(cat /tmp/rpemd.pid)"; wait "$(cat /tmp/rpemd.pid)" 2>/dev/null; }

run_steps() {  # name, extra rpem sim options
  name=$1; shift
  step "$name: -8 % steps of R_s and psi_m, sim options: $*"
  rm -rf /tmp/rpemd
  start_rpemd "$name"
  $listen_keyed --csv "$out/${name}_est.csv" --diagnostics > "$out/${name}_listen.txt" 2>&1 &
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
start_streaming faults
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
$cmd freeze --seq 5
$cmd unfreeze --seq 5                                # an old sequence number: rejected
$cmd unfreeze --seq 6 --save $keys/attacker/captured.bin   # the attacker captures it on the network
sleep 2
# The attacker, without the keys (issue 13): well-formed commands with larger sequence numbers, unsigned
# and under a guessed key; the captured command replayed and with one bit flipped; forged estimates.
echo "$(date +%s) attacker" >> "$out/faults_events.txt"
rpem command set --seq 1000 --psi-m 0.6 --r-s 1.2
rpem command --key $keys/attacker/guess.key set --seq 1001 --psi-m 0.6 --r-s 1.2
rpem command --key $keys/attacker/guess.key freeze --seq 1002
rpem command --resend $keys/attacker/captured.bin
rpem command --resend $keys/attacker/captured.bin --flip-bit 130
for i in 1 2 3; do rpem publish-estimate --psi-m 0.6 --r-s 1.2 --key $keys/attacker/publish.key; sleep 0.3; done
sleep 2
echo "$(date +%s) attacker end" >> "$out/faults_events.txt"
sleep 3                                              # diagnostics (1 Hz) after the attacks, before the kill
echo "$(date +%s) sigkill" >> "$out/faults_events.txt"
kill -KILL "$(cat /tmp/rpemd.pid)"
cp /tmp/rpemd/estimates.json "$out/killed_state.json" 2>/dev/null   # what the restart must resume from
sleep 1
start_rpemd restarted
sleep 2
rpem command --resend $keys/attacker/captured.bin       # still a replay: the sequence number persisted
sleep 2
stop_rpemd
kill $sim 2>/dev/null; wait $sim 2>/dev/null
kill -INT $listen; wait $listen
cp /tmp/rpemd/estimates.json "$out/restarted_state.json" 2>/dev/null

# All at once, for a fixed number of rounds: SIGHUP at 10 Hz through four configurations (two that load,
# one that does not, one that changes what only a restart applies), supervisory commands at 100 Hz, and
# vcan0 going down and up, while the drive streams. Checked: every command accepted applied once and in
# order, every reload applied or refused with a counted reason, the socket reopened, the state file
# whole; the loop's overrun rate against the quiet seconds before (tests/vm/check_daemon_suite.py).
step "storm: SIGHUP 100 x at 10 Hz, 1000 commands at 100 Hz, vcan0 down/up 5 x, all at once"
rm -rf /tmp/rpemd
cp $cfg /tmp/storm-a.yaml
{ cat $cfg; echo "  validity: {max_hold_s: 10}"; echo "  temperature: {reference_C: 25}"; } > /tmp/storm-b.yaml
{ cat $cfg; echo "  sauce: 1"; } > /tmp/storm-bad.yaml
{ cat $cfg; echo "  receive_thread: {policy: fifo, priority: 71}"; } > /tmp/storm-restart.yaml
cp /tmp/storm-a.yaml /tmp/storm.yaml
start_streaming storm /tmp/storm.yaml
pid=$(cat /tmp/rpemd.pid)
sleep 15
echo "$(date +%s) storm start" >> "$out/storm_events.txt"
$cmd unfreeze --seq 100 --repeat 1000 --interval-ms 10 2> "$out/storm_commands.txt" &
commands=$!
(
  i=0
  while [ $i -lt 100 ]; do
    case $((i % 4)) in 0) v=a ;; 1) v=b ;; 2) v=bad ;; *) v=restart ;; esac
    cp /tmp/storm-$v.yaml /tmp/storm.new && mv /tmp/storm.new /tmp/storm.yaml
    kill -HUP $pid
    sleep 0.1
    i=$((i + 1))
  done
) &
hups=$!
for k in 1 2 3 4 5; do ip link set vcan0 down; sleep 1.5; ip link set vcan0 up; sleep 1; done
wait $commands
wait $hups
echo "$(date +%s) storm end" >> "$out/storm_events.txt"
cp /tmp/storm-a.yaml /tmp/storm.new && mv /tmp/storm.new /tmp/storm.yaml
kill -HUP $pid
sleep 2
$cmd freeze --seq 2000                       # first: a set before it would adapt until the freeze came
$cmd set --seq 2001 --psi-m 1.123 --r-s 2.345
sleep 4
stop_rpemd
kill $sim 2>/dev/null; wait $sim 2>/dev/null
kill -INT $listen; wait $listen
cp /tmp/rpemd/estimates.json "$out/storm_state.json" 2>/dev/null
step "done"
