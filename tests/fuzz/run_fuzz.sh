#!/usr/bin/env bash
# Builds one libFuzzer target with clang and runs it from its committed seed corpus for a time budget (and
# any further libFuzzer options, e.g. -runs=10000000, or more corpus directories). ctest runs each target
# for 30 s (label fuzz); docs/benchmarks.md ("Fuzzing") records the long runs.
#   [RPEM_FUZZ_SANITIZERS=asan+ub|ub+leak] run_fuzz.sh BUILD_DIR TARGET [SECONDS] [libFuzzer options...]
# RPEM_FUZZ_SANITIZERS:
#   asan+ub  (default) AddressSanitizer + UndefinedBehaviorSanitizer (UB aborts), LeakSanitizer on;
#            built and run under BUILD_DIR/fuzz.
#   ub+leak  the long runs' fast build: UndefinedBehaviorSanitizer in trap mode (clang 14 links no UBSan
#            runtime beside standalone LeakSanitizer; UB kills the run and libFuzzer keeps the input) +
#            standalone LeakSanitizer, no ASan: several times the executions, memory errors unseen.
#            Under BUILD_DIR/fuzz-ub+leak. A long run is this build to the count, then every unit of the
#            corpus it grew replayed under asan+ub:
#              RPEM_FUZZ_SANITIZERS=ub+leak run_fuzz.sh B T SECONDS -runs=N
#              run_fuzz.sh B T 0 -runs=0 B/fuzz-ub+leak/T/corpus
# The targets, one row each: its entry point, what it links, its seed corpus (and dictionary corpus.dict).
set -euo pipefail
build=$(cd "$1" && pwd)
target=$2
seconds=${3:-30}
shift $(($# < 3 ? $# : 3))
repo=$(cd "$(dirname "$0")/../.." && pwd)
# The target runs from its own directory: corpus directories given relative to here are made absolute.
args=()
for a in "$@"; do [[ $a != -* && -d $a ]] && a=$(cd "$a" && pwd); args+=("$a"); done
set -- "${args[@]}"

core=("$repo"/core/src/*.cpp)
io=("$repo"/io/src/*.cpp "$build"/io/*.cpp "$repo"/can/src/{signal_map,sample_clock}.cpp)  # io's generated sources (compiled-in
# configuration and log map) are configure_file outputs in $build/io; io reads signal maps
# The YAML readers' inputs cost yaml-cpp about one allocation per byte, and under ASan an allocation is most
# of the cost (docs/benchmarks.md, "Fuzzing"). -max_len: every key of the reader in one file is 2.1 kB
# (io/fuzz/corpus/machine_config/every-key.yaml, sim/fuzz/corpus/every-key.yaml) and the largest seed 2.9 kB,
# so 3 kB reaches every check while the longest (and slowest) junk stays bounded. A 16 MB quarantine (ASan's
# default: 256 MB) still holds every block freed within one input (at most about 1 MB at 3 kB), so a
# use-after-free inside an input is still caught, while the allocator stops cycling through 256 MB of
# fresh pages (half the replay's CPU time).
yaml_opts=(-max_len=3072)
yaml_asan=quarantine_size_mb=16
opts=() asan= lcm=
case $target in
  fuzz_decoder)        main=can/fuzz/fuzz_decoder.cpp;        objs=("$repo"/can/src/{decoder,e2e,sample_clock}.cpp)
                       corpus=can/fuzz/corpus ;;
  fuzz_vesc)           main=can/fuzz/fuzz_vesc.cpp;           objs=("$repo/can/src/vesc.cpp" "$repo/can/src/e2e.cpp")
                       corpus=can/fuzz/corpus_vesc ;;
  fuzz_signal_map)     main=can/fuzz/fuzz_signal_map.cpp;     objs=("$repo"/can/src/{signal_map,sample_clock}.cpp)
                       corpus=can/fuzz/corpus_signal_map ;;
  fuzz_log_source)     main=io/fuzz/fuzz_log_source.cpp;      objs=("${io[@]}" "${core[@]}")
                       corpus=io/fuzz/corpus/log_source; asan=$yaml_asan ;;
  fuzz_machine_config) main=io/fuzz/fuzz_machine_config.cpp;  objs=("${io[@]}" "${core[@]}")
                       corpus=io/fuzz/corpus/machine_config; opts=("${yaml_opts[@]}") asan=$yaml_asan ;;
  fuzz_scenario)       main=sim/fuzz/fuzz_scenario.cpp;       objs=("$repo"/sim/src/*.cpp "$repo"/can/src/{vesc_firmware,vesc,e2e}.cpp "${io[@]}" "${core[@]}")
                       corpus=sim/fuzz/corpus; opts=("${yaml_opts[@]}") asan=$yaml_asan ;;
  fuzz_command)        main=daemon/fuzz/fuzz_command.cpp;     objs=("$repo/daemon/src/command_gate.cpp" "$repo/auth/src/mac.cpp" "$repo/auth/src/key.cpp")
                       corpus=daemon/fuzz/corpus
                       lcm=1 ;;  # rpemd's RPEM_COMMAND entry point: the LCM types are generated in the build
  *) echo "run_fuzz: unknown target $target" >&2; exit 2 ;;
esac
[[ -f $build/io/builtin_config.cpp ]] || { echo "run_fuzz: configure $build first (it generates io/builtin_config.cpp)" >&2; exit 2; }

case ${RPEM_FUZZ_SANITIZERS:-asan+ub} in
  asan+ub) sanitize=address,undefined trap= dir=$build/fuzz ;;
  ub+leak) sanitize=undefined,leak trap=-fsanitize-trap=undefined dir=$build/fuzz-ub+leak ;;
  *) echo "run_fuzz: RPEM_FUZZ_SANITIZERS is asan+ub or ub+leak, not $RPEM_FUZZ_SANITIZERS" >&2; exit 2 ;;
esac
mkdir -p "$dir/$target/corpus"
# Generated LCM types up to date (a no-op when nothing changed): never fuzz against stale ones.
if [[ -n $lcm ]]; then
  cmake --build "$build" --target rpem_lcm_cpp >"$dir/$target.lcm.log" 2>&1 ||
    { cat "$dir/$target.lcm.log"; echo "run_fuzz: the LCM types did not build" >&2; exit 1; }
fi

# A small ninja build under $dir: each source compiles once (header dependencies tracked) and the
# targets share the objects; a lock serialises builds when ctest runs targets in parallel.
{
  echo "cxx = clang++ -std=c++20 -O1 -g -fno-sanitize-recover=undefined $trap -I$repo/can/include -I$repo/core/include" \
       "-I$repo/io/include -I$repo/sim/include -I$repo/daemon/include -I$repo/auth/include -isystem /usr/include/eigen3" \
       "-isystem $build/lcm_types/cpp -I$build/lcm_types/mirror -I$repo/lcm_types/include"
  echo "rule cc"
  echo "  command = \$cxx -fsanitize=fuzzer-no-link,$sanitize -MD -MF \$out.d -c \$in -o \$out"
  echo "  depfile = \$out.d"
  echo "  deps = gcc"
  echo "rule link"
  echo "  command = \$cxx -fsanitize=fuzzer,$sanitize \$in -lyaml-cpp -lsodium -o \$out"
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
