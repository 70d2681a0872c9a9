#!/usr/bin/env bash
# Sets up this machine (Debian packages), builds, and runs rpemd — on the built-in simulated drive
# unless arguments say otherwise (e.g. `scripts/run.sh --can can0`, `--config FILE`). Ctrl-C stops it.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DRPEM_BUILD_TESTS=OFF -DRPEM_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build/release --target rpemd rpem rpem_lcm_jar
echo "run.sh: starting rpemd (watch it with: build/release/tools/rpem listen  or  build/release/tools/rpem-lcm-spy)" >&2
exec build/release/daemon/rpemd "$@"
