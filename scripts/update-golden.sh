#!/usr/bin/env bash
# Regenerates tests/golden/reproduce.json from `rpem reproduce` (review the diff before committing:
# the regression test is two-sided, so any change, better or worse, must be deliberate).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build/golden -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRPEM_BUILD_TESTS=OFF -DRPEM_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build/golden --target rpem
out=$(mktemp -d)
build/golden/tools/rpem reproduce --out "$out"
cp "$out/reproduce.json" tests/golden/reproduce.json
git --no-pager diff --stat tests/golden/reproduce.json || true
