#!/usr/bin/env bash
# Regenerates docs/figures/reproduction/ — the figures, comparison.md and reproduce.json that
# docs/reproduction.md shows — from `rpem reproduce`. reproduce.json is also the golden file that
# tests/analysis/test_reproduction.cpp holds the reproduction to (two-sided: any change, better or worse,
# must be deliberate), so review the diff before committing.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build/golden -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRPEM_BUILD_TESTS=OFF -DRPEM_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build/golden --target rpem
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
build/golden/tools/rpem reproduce --out "$out"
dest=docs/figures/reproduction
rm -f "$dest"/*.png "$dest"/comparison.md "$dest"/reproduce.json
cp "$out"/*.png "$out/comparison.md" "$out/reproduce.json" "$dest/"
git --no-pager diff --stat -- "$dest" || true
