#!/usr/bin/env bash
# Sets up a fresh machine and runs the whole test suite, as CI does (.ci/run):
#   1. installs the Debian packages (scripts/setup.sh, idempotent)
#   2. builds with warnings as errors and runs every ctest label (unit, cli, slow, vcan, …)
#   3. builds the unit tests of core, io, can, sim, analysis and auth with AddressSanitizer +
#      UndefinedBehaviorSanitizer and runs them (the daemon's real-time loop is covered by its own
#      allocation and VM tests; rpemd and the rpem tool are left out of this build)
#   4. builds rpemd and the daemon's tests with ThreadSanitizer and runs them — the storm test drives
#      the instrumented rpemd with reloads and commands at once — expecting no report (suppressed: only
#      the uninstrumented LCM/GLib internals, tests/daemon/tsan.supp)
#   5. the format and lint gates (scripts/lint.py; docs/architecture.md, "Format and lint"): clang-format
#      first (seconds), clang-tidy over the production translation units of build/ci last
# The sanitizer trees of 3 and 4 compile at nice 19 while step 2's tests run: they take only the CPU the
# tests leave idle (the VM suites' real-time pacing, the serial package test, the last test's tail) and
# yield it otherwise (CFS weight 15 against 1024), so a test's share of the CPU is what it was without them.
# clang-tidy on the production units (the chosen checks over build/ci's 22 unity batches: ≈ 370 s of CPU, a
# quarter of what each source alone costs; docs/benchmarks.md, "Format and lint gates") follows them at nice 19
# too: it yields to the sanitizer tests and delays nothing a test waits for. Its CPU is paid for by what the
# trees no longer compile (same benchmarks section): build/ci is Release, the -O3 -DNDEBUG of RelWithDebInfo without -g (g++ emits the
# same code with or without debug information, -fcompare-debug's guarantee: what runs is what ran), a third
# less compiler time; the sanitizer trees keep line tables only (-g1: every report still names file:line).
# All three trees are unity builds (RPEM_UNITY_BUILD, CMakeLists.txt): each target's sources compiled in batches,
# the shared headers parsed once a batch (docs/benchmarks.md, "The README test command on a fresh clone", has the
# compile CPU saved); developer trees are not. clang-tidy checks each batch as one unit, its sources through it
# (the same findings as each source alone, the shared headers matched once a batch: scripts/lint.py --per-source
# is the slower way, the same benchmarks section compares them).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

scripts/setup.sh
if ! scripts/lint.py --format; then
  echo "test.sh: the format gate failed: scripts/lint.py --fix-format rewrites the files listed above" >&2
  exit 1
fi

cmake -S . -B build/ci -G Ninja -DCMAKE_BUILD_TYPE=Release -DRPEM_WERROR=ON -DRPEM_UNITY_BUILD=ON
cmake --build build/ci -j "$jobs"

sanitizer_builds() {
  cmake -S . -B build/sanitize -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g1" -DRPEM_WERROR=ON \
    -DRPEM_SANITIZE=address,undefined -DRPEM_BUILD_BENCHMARKS=OFF -DRPEM_BUILD_DAEMON=OFF -DRPEM_BUILD_TOOLS=OFF \
    -DRPEM_UNITY_BUILD=ON
  cmake --build build/sanitize -j "$jobs" --target test_core test_io test_can test_sim test_sim_vesc test_analysis \
    test_auth test_indep_drive indep_drive_log test_indep_thermal indep_thermal_plant
  cmake -S . -B build/tsan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DRPEM_WERROR=ON \
    -DRPEM_SANITIZE=thread -DRPEM_BUILD_BENCHMARKS=OFF -DRPEM_BUILD_TOOLS=OFF -DRPEM_UNITY_BUILD=ON
  cmake --build build/tsan -j "$jobs" --target rpemd test_daemon test_daemon_allocations test_daemon_storm
}
sanitizer_log=build/sanitizer-builds.log
tidy_log=build/lint-tidy.log
set -m  # the builds in a process group of their own, so that a failing ctest stops all of them
(renice -n 19 -p "$BASHPID" >/dev/null && sanitizer_builds) </dev/null >"$sanitizer_log" 2>&1 &
sanitizer_pid=$!
# clang-tidy once the sanitizer builds are done (they gate the sanitizer tests; it gates nothing)
(renice -n 19 -p "$BASHPID" >/dev/null && while kill -0 "$sanitizer_pid" 2>/dev/null; do sleep 5; done &&
  scripts/lint.py --tidy -p build/ci -j "$jobs") </dev/null >"$tidy_log" 2>&1 &
tidy_pid=$!
set +m
# (a stopped clang-tidy, below, gets its TERM when continued)
trap 'kill -- "-$sanitizer_pid" "-$tidy_pid" 2>/dev/null; kill -CONT -- "-$tidy_pid" 2>/dev/null || true' EXIT
ctest --test-dir build/ci --output-on-failure -j "$jobs" --timeout 1800 -LE lint
echo "test.sh: waiting for the sanitizer builds (log: $sanitizer_log)"
if ! wait "$sanitizer_pid"; then
  cat "$sanitizer_log"
  echo "test.sh: the sanitizer builds failed" >&2
  exit 1
fi

# Each test binary runs in GoogleTest shards, not a process per case (tests/CMakeLists.txt, rpem_add_test, says
# why). The compile_fail cases (label compile) are left out: their compiler command is their own, whatever the
# tree's flags, and it ran in build/ci.
UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1 \
  ctest --test-dir build/sanitize --output-on-failure -j "$jobs" -L unit -LE '^compile$'
# The ThreadSanitizer daemon tests, one process each. The last is the storm (a real rpemd's loop and its control
# thread under commands at 1 kHz over UDP): clang-tidy is paused while it runs, so that its two nice-19 jobs take
# no CPU from it (a fresh-clone run of 90fd8e7 failed the storm's "≥ 90 % of the commands arrive" with clang-tidy
# beside it: 1 479 of 3 002; docs/benchmarks.md). The two before it (about a minute, mostly one thread) leave a
# core to clang-tidy.
for t in test_daemon test_daemon_allocations test_daemon_storm; do
  [[ $t == test_daemon_storm ]] && { kill -STOP -- "-$tidy_pid" 2>/dev/null || true; }
  TSAN_OPTIONS="suppressions=$PWD/tests/daemon/tsan.supp halt_on_error=1 second_deadlock_stack=1" \
    "build/tsan/tests/daemon/$t" --gtest_brief=1
done
kill -CONT -- "-$tidy_pid" 2>/dev/null || true
echo "test.sh: waiting for clang-tidy (log: $tidy_log)"
if ! wait "$tidy_pid"; then
  cat "$tidy_log"
  echo "test.sh: clang-tidy found something (scripts/lint.py --tidy -p build/ci lists it)" >&2
  exit 1
fi
trap - EXIT
tail -n 1 "$tidy_log"
echo "test.sh: all tests passed"
