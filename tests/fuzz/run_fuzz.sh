#!/usr/bin/env bash
# Builds a libFuzzer target with clang (libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer) and
# runs it from its committed corpus for a time budget. ctest runs each short; the docs record long runs
# (decoder: docs/can-protocol.md; command: docs/rpemd.md).
#   run_fuzz.sh BUILD_DIR [SECONDS] [decoder|command] [extra libFuzzer options…]
set -euo pipefail
build=$(cd "$1" && pwd)
seconds=${2:-30}
target=${3:-decoder}
shift $(($# < 3 ? $# : 3))
repo=$(cd "$(dirname "$0")/../.." && pwd)
includes=(-I "$repo/core/include" -isystem /usr/include/eigen3)
case $target in
  decoder)  # the telemetry decoder (can/)
    sources=("$repo/can/fuzz/fuzz_decoder.cpp" "$repo/can/src/decoder.cpp" "$repo/can/src/e2e.cpp")
    includes+=(-I "$repo/can/include")
    corpus_src=$repo/can/fuzz/corpus ;;
  command)  # rpemd's RPEM_COMMAND entry point (daemon/); the LCM types are generated in the build
    [[ -f $build/lcm_types/cpp/rpem/command_t.hpp ]] || cmake --build "$build" --target rpem_lcm_cpp >/dev/null
    sources=("$repo/daemon/fuzz/fuzz_command.cpp" "$repo/daemon/src/command_gate.cpp")
    includes+=(-I "$repo/daemon/include" -I "$repo/io/include" -I "$repo/can/include" -I "$repo/sim/include"
               -isystem "$build/lcm_types/cpp")
    corpus_src=$repo/daemon/fuzz/corpus ;;
  *) echo "run_fuzz: unknown target $target" >&2; exit 2 ;;
esac
out=$build/fuzz/$target
mkdir -p "$out/corpus"
clang++ -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  "${includes[@]}" "${sources[@]}" -o "$out/fuzz_$target"
cp -n "$corpus_src"/* "$out/corpus/" 2>/dev/null || true
cd "$out"
"$out/fuzz_$target" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$out/crash-" "$@" \
  "$out/corpus" 2>&1 | tail -n 25
echo "run_fuzz: $target: no crash in ${seconds} s"
