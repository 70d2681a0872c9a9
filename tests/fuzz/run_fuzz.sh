#!/usr/bin/env bash
# Builds one CAN decoder fuzzer with clang (libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer) and
# runs it from its committed corpus for a time budget (and any further libFuzzer options, e.g.
# -runs=10000000). ctest runs each 60 s (label fuzz); docs/can-protocol.md, docs/can-vesc.md and
# docs/sources.md record long runs.
#   run_fuzz.sh BUILD_DIR TARGET [SECONDS] [libFuzzer options...]
set -euo pipefail
build=$(cd "$1" && pwd)
target=$2
seconds=${3:-30}
shift $(($# < 3 ? $# : 3))
repo=$(cd "$(dirname "$0")/../.." && pwd)
case $target in
  fuzz_decoder)    objs=("$repo/can/src/decoder.cpp" "$repo/can/src/e2e.cpp"); corpus=$repo/can/fuzz/corpus ;;
  fuzz_vesc)       objs=("$repo/can/src/vesc.cpp" "$repo/can/src/e2e.cpp"); corpus=$repo/can/fuzz/corpus_vesc ;;
  fuzz_signal_map) objs=("$repo/can/src/signal_map.cpp"); corpus=$repo/can/fuzz/corpus_signal_map ;;
  *) echo "run_fuzz: unknown target $target (fuzz_decoder, fuzz_vesc, fuzz_signal_map)" >&2; exit 2 ;;
esac
out=$build/fuzz/$target
mkdir -p "$out/corpus"
clang++ -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -I "$repo/can/include" -I "$repo/core/include" -isystem /usr/include/eigen3 \
  "$repo/can/fuzz/$target.cpp" "${objs[@]}" -o "$out/$target"
cp -n "$corpus"/* "$out/corpus/" 2>/dev/null || true
cd "$out"
"./$target" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$out/crash-" "$@" corpus 2>&1 | tail -n 25
echo "run_fuzz: $target: no crash in ${seconds} s"
