#!/usr/bin/env bash
# Builds the decoder fuzzer with clang (libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer) and
# runs it from the committed corpus for a time budget. ctest runs it short; docs/can-protocol.md records
# a long run.   run_fuzz.sh BUILD_DIR [SECONDS]
set -euo pipefail
build=$(cd "$1" && pwd)
seconds=${2:-30}
repo=$(cd "$(dirname "$0")/../.." && pwd)
out=$build/fuzz
mkdir -p "$out/corpus"
clang++ -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -I "$repo/can/include" -I "$repo/core/include" -isystem /usr/include/eigen3 \
  "$repo/can/fuzz/fuzz_decoder.cpp" "$repo/can/src/decoder.cpp" "$repo/can/src/e2e.cpp" \
  -o "$out/fuzz_decoder"
cp -n "$repo"/can/fuzz/corpus/* "$out/corpus/" 2>/dev/null || true
cd "$out"
"$out/fuzz_decoder" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$out/crash-" \
  "$out/corpus" 2>&1 | tail -n 25
echo "run_fuzz: no crash in ${seconds} s"
