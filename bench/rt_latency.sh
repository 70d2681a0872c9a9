#!/usr/bin/env bash
# rpemd's estimator loop against cyclictest at the same period, priority and CPU on the same machine.
# The two alternate in slices (ROUNDS × SLICE seconds each), so the shared machine's noise falls on
# both alike; their histograms are summed. Prints p50/p99/max, the ratios, rpemd's overruns against the
# periods in which cyclictest itself woke more than a period late, and rpemd's CPU use per thread.
#   rt_latency.sh BUILD_DIR [SECONDS] [host|vm|both]      (SECONDS per program, default 60)
# host: sim source, 125 µs, SCHED_FIFO 80 on CPU 1 (other threads on CPU 0).
# vm:   CAN source in the PREEMPT_RT VM (emulated: 1 ms), `rpem sim --can` streaming; also CAN receive →
#       LCM publish latency.
set -euo pipefail
build=$(cd "$1" && pwd)
seconds=${2:-60}
where=${3:-both}
repo=$(cd "$(dirname "$0")/.." && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
rounds=6
slice=$((seconds / rounds))

report() {  # label, period µs, cyclictest histograms…, --, rpemd histograms…
  python3 - "$@" <<'PY'
import sys
label, period = sys.argv[1], int(sys.argv[2])
args = sys.argv[3:]
split = args.index("--")
def load(files):
    counts, overflow, mx = {}, 0, 0
    for f in files:
        for line in open(f):
            if line.startswith("# Histogram Overflows"):
                overflow += sum(int(x) for x in line.split(":")[1].split())
            elif line.startswith("# Max Latencies"):
                mx = max([mx] + [int(float(x)) for x in line.split(":")[1].split()])
            elif not line.startswith("#") and line.strip():
                us, n = line.split()[:2]
                counts[int(us)] = counts.get(int(us), 0) + int(n)
    total = sum(counts.values()) + overflow
    def pct(q):
        seen = 0
        for us in sorted(counts):
            seen += counts[us]
            if seen >= q * total:
                return us
        return mx
    late = sum(n for us, n in counts.items() if us >= period) + overflow
    return pct(0.5), pct(0.99), max([mx] + list(counts)), total, late
c = load(args[:split])
r = load(args[split + 1:])
print(f"{label}: cyclictest  p50 {c[0]} µs, p99 {c[1]} µs, max {c[2]} µs; {c[4]} of {c[3]} wake-ups a period or more late")
print(f"{label}: rpemd loop  p50 {r[0]} µs, p99 {r[1]} µs, max {r[2]} µs; {r[4]} of {r[3]} wake-ups a period or more late")
print(f"{label}: ratio rpemd/cyclictest  p50 {r[0] / max(1, c[0]):.2f}, p99 {r[1] / max(1, c[1]):.2f}")
PY
}

host() {
  cat >"$out/rpemd-host.yaml" <<YAML
daemon:
  loop: {period_s: 125.0e-6, realtime: required, thread: {policy: fifo, priority: 80, cpu: 1}}
  receive_thread: {policy: fifo, priority: 70, cpu: 0}
  publish_thread: {policy: other, cpu: 0}
  state: {file: $out/state.json}
  status_interval_s: 0
YAML
  # The same loop with timer anticipation (loop.wake_ahead_s: auto): after its first second it sleeps
  # until its median wake-up latency before each deadline, then spins to it.
  sed -e 's/period_s: 125.0e-6,/period_s: 125.0e-6, wake_ahead_s: auto,/' "$out/rpemd-host.yaml" >"$out/rpemd-ahead.yaml"
  # The same loop with the thermal network's Kalman filter on every sample (issue 24 item 6: the fusion must
  # not move the latency figures): a two-node network for the built-in drive (docs/thermal.md, "In rpemd").
  cat "$out/rpemd-host.yaml" - >"$out/rpemd-thermal.yaml" <<YAML
thermal:
  nodes:
    - {name: winding, capacitance_J_per_K: 3000, to_coolant_W_per_K: 2}
    - {name: magnet, capacitance_J_per_K: 7000, to_coolant_W_per_K: 4}
  conductances: [{from: winding, to: magnet, W_per_K: 12}]
  coolant_C: 35
YAML
  # The same daemon kept entirely on CPU 0: the load rpemd's own other threads put beside its loop.
  sed -e 's/cpu: 1}/cpu: 0}/' "$out/rpemd-host.yaml" >"$out/rpemd-cpu0.yaml"
  echo "== host: $rounds × ${slice} s each of cyclictest -m -p 80 -i 125 -a 1 (alone; and beside an rpemd kept on CPU 0)"
  echo "   and of rpemd (loop 125 µs, FIFO 80, CPU 1, sim source; its other threads on CPU 0), plain and with"
  echo "   loop.wake_ahead_s: auto, and plain with the thermal fusion on"
  local cyc=() cycl=() rpm=() rpa=() rpt=()
  run_rpemd() {  # config, histogram, log; prints CPU use per thread when asked
    "$build/daemon/rpemd" --config "$1" --latency-histogram "$2" 2>"$3" &
    local pid=$!
    sleep "$slice"
    if [[ -n ${4:-} ]]; then
      for t in /proc/$pid/task/*; do
        echo "$(cat "$t/comm") $(awk '{print $14 + $15}' "$t/stat")"
      done | awk -v s="$slice" -v l="$4" '{printf "  cpu (%s) %-14s %5.1f %% of a core\n", l, $1, $2 / s}'
    fi
    kill -TERM $pid
    wait $pid || true
  }
  for r in $(seq 1 $rounds); do
    cyclictest -m -q -p 80 -i 125 -a 1 -t 1 -D "$slice" -h 20000 --histfile="$out/c$r.hist" >/dev/null
    cyc+=("$out/c$r.hist")
    "$build/daemon/rpemd" --config "$out/rpemd-cpu0.yaml" 2>/dev/null >/dev/null &
    local load=$!
    sleep 1
    cyclictest -m -q -p 80 -i 125 -a 1 -t 1 -D "$slice" -h 20000 --histfile="$out/l$r.hist" >/dev/null
    kill -TERM $load
    wait $load || true
    cycl+=("$out/l$r.hist")
    run_rpemd "$out/rpemd-host.yaml" "$out/r$r.hist" "$out/r$r.txt" "$([[ $r -eq 1 ]] && echo plain)"
    rpm+=("$out/r$r.hist")
    run_rpemd "$out/rpemd-ahead.yaml" "$out/a$r.hist" "$out/a$r.txt" "$([[ $r -eq 1 ]] && echo ahead)"
    rpa+=("$out/a$r.hist")
    run_rpemd "$out/rpemd-thermal.yaml" "$out/t$r.hist" "$out/t$r.txt" "$([[ $r -eq 1 ]] && echo thermal)"
    rpt+=("$out/t$r.hist")
  done
  grep -h "overruns" "$out"/r*.txt | awk '{o += $(NF-4); p += $(NF-1)} END {printf "host: rpemd overruns %d in %d periods\n", o, p}'
  report host 125 "${cyc[@]}" -- "${rpm[@]}"
  grep -h "overruns" "$out"/a*.txt | awk '{o += $(NF-4); p += $(NF-1)} END {printf "host, wake-ahead auto: rpemd overruns %d in %d periods\n", o, p}'
  grep -h "calibrated" "$out"/a*.txt | sed 's/^/host, wake-ahead auto: /'
  report "host, wake-ahead auto" 125 "${cyc[@]}" -- "${rpa[@]}"
  grep -h "overruns" "$out"/t*.txt | awk '{o += $(NF-4); p += $(NF-1)} END {printf "host, thermal fusion on: rpemd overruns %d in %d periods\n", o, p}'
  report "host, thermal fusion on" 125 "${cyc[@]}" -- "${rpt[@]}"
  report "host, cyclictest beside rpemd on CPU 0" 125 "${cycl[@]}" -- "${rpm[@]}"
}

vm() {
  cat >"$out/stream.yaml" <<YAML
name: latency-stream
machine: builtin:paper-ipmsm
duration_s: $((seconds * 2 / 5 + 4))
inverter: {model: averaged}
sensors: {current_noise_A: 0.02, current_lsb_A: 0.01, encoder_counts: 16384}
initial: {speed_rpm: 300, torque_Nm: 13.04, u_dc_V: 220}
YAML
  cat >"$out/rpemd-vm.yaml" <<YAML
daemon:
  source: {type: can, can: {interface: vcan0}}
  loop: {period_s: 1.0e-3, realtime: required, thread: {policy: fifo, priority: 80, cpu: 1}}
  receive_thread: {policy: fifo, priority: 70, cpu: 0}
  state: {file: /tmp/state.json}
  status_interval_s: 0
YAML
  echo "== PREEMPT_RT VM (emulated): ${seconds} s each, with the drive streaming into vcan0 both times (same load):"
  echo "   cyclictest -p 80 -i 1000 -a 1 beside rpem record (the receiving load), then rpemd (CAN source, loop 1 ms)"
  "$repo/tests/vm/vm_rig.sh" run --timeout $((seconds * 8 + 300)) --share "$out" --file "$build/daemon/rpemd" \
    --file "$build/tools/rpem" --file "$out/stream.yaml" --file "$out/rpemd-vm.yaml" -- "
      rpem record --can vcan0 --out /tmp/recorded.csv --idle-timeout 3 > /dev/null 2>&1 &
      rec=\$!
      sleep 1
      rpem sim --scenario stream.yaml --can vcan0 --rate 0.4 > /dev/null 2>&1 &
      sim=\$!
      sleep 1
      cyclictest -m -q -p 80 -i 1000 -a 1 -t 1 -D $seconds -h 20000 --histfile=/host/cvm.hist > /dev/null
      kill \$sim; wait \$rec
      rpemd --config rpemd-vm.yaml --latency-histogram /host/rvm.hist 2> /host/rpemd-vm.txt &
      pid=\$!
      sleep 1
      rpem sim --scenario stream.yaml --can vcan0 --rate 0.4 2> /dev/null
      for t in /proc/\$pid/task/*; do echo \"\$(cat \$t/comm) \$(awk '{print \$14 + \$15}' \$t/stat)\"; done > /host/cpu-vm.txt
      kill -TERM \$pid; wait \$pid" >/dev/null 2>&1 || true
  grep -E "overruns|publish" "$out/rpemd-vm.txt" | sed 's/^/vm: /'
  awk -v s="$((seconds + 1))" '{printf "  cpu %-14s %5.1f %% of an emulated core\n", $1, $2 / s}' "$out/cpu-vm.txt"
  report vm 1000 "$out/cvm.hist" -- "$out/rvm.hist"
}

date -u
lscpu | grep -E "^Model name|^CPU\(s\)" | sed 's/  */ /g'
uname -r
if [[ $where == host || $where == both ]]; then host; fi
if [[ $where == vm || $where == both ]]; then vm; fi
