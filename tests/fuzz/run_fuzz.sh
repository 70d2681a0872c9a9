#!/usr/bin/env bash
# Builds one libFuzzer target with clang (libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer, leak
# detection on) and runs it from its committed seed corpus for a time budget (and any further libFuzzer
# options, e.g. -runs=10000000). ctest runs each target for 60 s (label fuzz); docs/benchmarks.md
# ("Fuzzing") records the long runs.
#   run_fuzz.sh BUILD_DIR TARGET [SECONDS] [libFuzzer options...]
# The targets, one row each: its entry point, what it links, its seed corpus (and dictionary corpus.dict).
set -euo pipefail
build=$(cd "$1" && pwd)
target=$2
seconds=${3:-30}
shift $(($# < 3 ? $# : 3))
repo=$(cd "$(dirname "$0")/../.." && pwd)

core=("$repo"/core/src/*.cpp)
io=("$repo"/io/src/*.cpp "$build/io/builtin_config.cpp" "$repo/can/src/signal_map.cpp")  # io reads signal maps
# The YAML readers' inputs cost yaml-cpp about one allocation per byte, and under ASan an allocation is most
# of the cost (docs/benchmarks.md, "Fuzzing"). -max_len: every key of the reader in one file is 2.1 kB
# (io/fuzz/corpus/machine_config/every-key.yaml, sim/fuzz/corpus/every-key.yaml) and the largest seed 2.9 kB,
# so 3 kB reaches every check while the longest (and slowest) junk stays bounded. A 16 MB quarantine (ASan's
# default: 256 MB) still holds every block freed within one input (at most about 1 MB at 3 kB), so a
# use-after-free inside an input is still caught, while the allocator stops cycling through 256 MB of
# fresh pages (half the replay's CPU time).
yaml_opts=(-max_len=3072)
yaml_asan=quarantine_size_mb=16
opts=() asan=
case $target in
  fuzz_decoder)        main=can/fuzz/fuzz_decoder.cpp;        objs=("$repo/can/src/decoder.cpp" "$repo/can/src/e2e.cpp")
                       corpus=can/fuzz/corpus ;;
  fuzz_vesc)           main=can/fuzz/fuzz_vesc.cpp;           objs=("$repo/can/src/vesc.cpp" "$repo/can/src/e2e.cpp")
                       corpus=can/fuzz/corpus_vesc ;;
  fuzz_signal_map)     main=can/fuzz/fuzz_signal_map.cpp;     objs=("$repo/can/src/signal_map.cpp")
                       corpus=can/fuzz/corpus_signal_map ;;
  fuzz_drive_log)      main=io/fuzz/fuzz_drive_log.cpp;       objs=("${io[@]}" "${core[@]}")
                       corpus=io/fuzz/corpus/drive_log ;;
  fuzz_machine_config) main=io/fuzz/fuzz_machine_config.cpp;  objs=("${io[@]}" "${core[@]}")
                       corpus=io/fuzz/corpus/machine_config; opts=("${yaml_opts[@]}") asan=$yaml_asan ;;
  fuzz_scenario)       main=sim/fuzz/fuzz_scenario.cpp;       objs=("$repo"/sim/src/*.cpp "${io[@]}" "${core[@]}")
                       corpus=sim/fuzz/corpus; opts=("${yaml_opts[@]}") asan=$yaml_asan ;;
  fuzz_command)        main=daemon/fuzz/fuzz_command.cpp;     objs=("$repo/daemon/src/command_gate.cpp" "$repo/auth/src/mac.cpp")
                       corpus=daemon/fuzz/corpus
                       # rpemd's RPEM_COMMAND entry point; the LCM types are generated in the build
                       [[ -f $build/lcm_types/cpp/rpem/command_t.hpp ]] || cmake --build "$build" --target rpem_lcm_cpp >/dev/null ;;
  *) echo "run_fuzz: unknown target $target" >&2; exit 2 ;;
esac
[[ -f $build/io/builtin_config.cpp ]] || { echo "run_fuzz: configure $build first (it generates io/builtin_config.cpp)" >&2; exit 2; }

# A small ninja build under BUILD_DIR/fuzz: each source compiles once (header dependencies tracked) and
# the targets share the objects; a lock serialises builds when ctest runs targets in parallel.
dir=$build/fuzz
mkdir -p "$dir/$target/corpus"
{
  echo "cxx = clang++ -std=c++20 -O1 -g -fno-sanitize-recover=undefined -I$repo/can/include -I$repo/core/include" \
       "-I$repo/io/include -I$repo/sim/include -I$repo/daemon/include -I$repo/auth/include -isystem /usr/include/eigen3" \
       "-isystem $build/lcm_types/cpp"
  echo "rule cc"
  echo "  command = \$cxx -fsanitize=fuzzer-no-link,address,undefined -MD -MF \$out.d -c \$in -o \$out"
  echo "  depfile = \$out.d"
  echo "  deps = gcc"
  echo "rule link"
  echo "  command = \$cxx -fsanitize=fuzzer,address,undefined \$in -lyaml-cpp -lsodium -o \$out"
  list=()
  for src in "$repo/$main" "${objs[@]}"; do
    rel=${src#"$repo"/}
    rel=${rel#"$build"/}
    obj=obj/${rel//\//_}.o
    echo "build $obj: cc $src"
    list+=("$obj")
  done
  echo "build $target/$target: link ${list[*]}"
} >"$dir/$target.ninja"
flock "$dir/.lock" ninja -j "$(nproc)" -C "$dir" -f "$target.ninja" "$target/$target" >"$dir/$target.build.log" 2>&1 ||
  { cat "$dir/$target.build.log"; echo "run_fuzz: $target did not build" >&2; exit 1; }

cp -n "$repo/$corpus"/* "$dir/$target/corpus/" 2>/dev/null || true
dict=()
[[ -f $repo/$corpus.dict ]] && dict=(-dict="$repo/$corpus.dict")
cd "$dir/$target"
[[ -n $asan ]] && export ASAN_OPTIONS=${ASAN_OPTIONS:-$asan}
"./$target" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$dir/$target/crash-" "${dict[@]}" "${opts[@]}" "$@" \
  corpus 2>&1 | tail -n 60
echo "run_fuzz: $target: no crash, leak or UB report"
