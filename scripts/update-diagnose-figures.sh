#!/usr/bin/env bash
# Regenerates docs/figures/diagnose/ — the two worked examples docs/diagnose.md shows (a hidden dead time
# on the simulated bench; the Paderborn bench profile) — by running the commands that page gives, and
# prints their summaries for the page's quoted figures. Review the diff before committing.
#   scripts/update-diagnose-figures.sh [BUILD_DIR]   (default build/golden, configured as update-golden.sh does)
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)
build=${1:-build/golden}
[[ -f $build/build.ninja ]] ||
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRPEM_BUILD_TESTS=OFF -DRPEM_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" --target rpem
rpem=$(cd "$build" && pwd)/tools/rpem
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# The page's commands with relative paths, so the reports name their inputs as the page does.
cd "$out"
for d in config data scenarios scripts; do ln -s "$repo/$d" "$d"; done

sed 's/inverter: {model/inverter: {dead_time_s: 1.5e-6, model/' scenarios/diagnose-bench.yaml >dt.yaml
"$rpem" sim --scenario dt.yaml --out dt.csv --truth dt-truth.csv 2>/dev/null
"$rpem" diagnose --log dt.csv --truth dt-truth.csv --switching-frequency-Hz 4000 --out deadtime

python3 scripts/paderborn_to_drive_log.py data/paderborn-motor-temperature/profile_A_every5th.csv profile.csv \
  --pole-pairs 4
"$rpem" diagnose --log profile.csv --config config/paderborn-pmsm.yaml --out paderborn

for example in deadtime paderborn; do
  dest=$repo/docs/figures/diagnose/$example
  rm -f "$dest"/*.png "$dest"/report.md
  cp "$example"/*.png "$example"/report.md "$dest/"
done
git -C "$repo" --no-pager diff --stat -- docs/figures/diagnose || true
