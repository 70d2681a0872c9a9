#!/usr/bin/env bash
# Builds a CAN decoder fuzzer with clang (libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer) and
# runs it from its committed corpus for a time budget. ctest runs them short; docs/can-protocol.md and
# docs/can-vesc.md record long runs.   run_fuzz.sh BUILD_DIR [SECONDS] [decoder|vesc] [extra libFuzzer flags…]
set -euo pipefail
build=$(cd "$1" && pwd)
seconds=${2:-30}
target=${3:-decoder}
shift $(( $# < 3 ? $# : 3 ))
repo=$(cd "$(dirname "$0")/../.." && pwd)
case "$target" in
  decoder) sources=("$repo/can/src/decoder.cpp" "$repo/can/src/e2e.cpp"); corpus=$repo/can/fuzz/corpus ;;
  vesc) sources=("$repo/can/src/vesc.cpp" "$repo/can/src/e2e.cpp"); corpus=$repo/can/fuzz/corpus_vesc ;;
  *) echo "run_fuzz: unknown target $target (decoder, vesc)" >&2; exit 64 ;;
esac
out=$build/fuzz/$target
mkdir -p "$out/corpus"
clang++ -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -I "$repo/can/include" -I "$repo/core/include" -isystem /usr/include/eigen3 \
  "$repo/can/fuzz/fuzz_$target.cpp" "${sources[@]}" -o "$out/fuzz_$target"
cp -n "$corpus"/* "$out/corpus/" 2>/dev/null || true
cd "$out"
"$out/fuzz_$target" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$out/crash-" "$@" \
  "$out/corpus" 2>&1 | tail -n 25
echo "run_fuzz: $target: no crash in ${seconds} s"
