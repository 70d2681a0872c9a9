#!/usr/bin/env bash
# Builds the benchmarks (Release) and runs them; prints the results as Markdown with the machine they
# ran on, for docs/benchmarks.md. Usage: bench/run_benchmarks.sh [estimator|simulator|can|diagnose|reproduce|all]
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-all}
cmake -S . -B build/bench -G Ninja -DCMAKE_BUILD_TYPE=Release -DRPEM_BUILD_TESTS=OFF >/dev/null
cmake --build build/bench --target bench_estimator bench_simulator bench_can bench_diagnose rpem >/dev/null
out=$(mktemp -d)
if [[ $what == all || $what == estimator ]]; then
  build/bench/bench/bench_estimator --benchmark_min_time=0.5 --benchmark_format=json >"$out/estimator.json"
fi
if [[ $what == all || $what == simulator ]]; then
  build/bench/bench/bench_simulator --benchmark_format=json >"$out/simulator.json"
fi
if [[ $what == all || $what == can ]]; then
  build/bench/bench/bench_can --benchmark_format=json >"$out/can.json"
fi
if [[ $what == all || $what == diagnose ]]; then
  build/bench/bench/bench_diagnose --benchmark_format=json >"$out/diagnose.json"
fi
python3 bench/format_benchmarks.py "$out"/*.json
if [[ $what == all || $what == reproduce ]]; then
  # The whole `rpem reproduce` (every case of Sections V and VI, one simulation per case on each core).
  TIMEFORMAT="| rpem reproduce, all cases, $(nproc) jobs | wall %R s | CPU %U s user + %S s system |"
  { time build/bench/tools/rpem reproduce --out "$out/reproduce" >/dev/null 2>&1; } 2>&1
fi
