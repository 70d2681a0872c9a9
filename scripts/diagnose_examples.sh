#!/usr/bin/env bash
# Regenerates every figure and number of docs/diagnose.md's examples (docs/figures/diagnose/) with the
# commands the document shows:
#   deadtime   — the simulated bench profile with a hidden 1.5 µs dead time (rpem sim, rpem diagnose);
#   offnominal — the independent generator's drive (tests/independent_drive/) whose machine is off its
#                configuration, with a dead time and a command delay of two periods;
#   paderborn  — the Paderborn profile A against the commissioned constant-parameter model;
#   paderborn-judged — profile A cut at the load change: the heat-up commissions and extends the model,
#                the cool-down is judged with the plain configuration and with the heat-up's extended.yaml.
# Usage: scripts/diagnose_examples.sh [BUILD_DIR]   (default build/ci; needs rpem and indep_drive_log)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/ci}
cmake --build "$build" --target rpem indep_drive_log >/dev/null
rpem=$build/tools/rpem
indep=$build/tests/independent_drive/indep_drive_log
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
figures=docs/figures/diagnose

keep() {  # keep a diagnosis' report and figures under docs/figures/diagnose/NAME
  rm -rf "${figures:?}/$2"
  mkdir -p "$figures/$2"
  cp "$1"/*.png "$1/report.md" "$1/diagnosis.json" "$1/extended.yaml" "$figures/$2/"
}

echo "== deadtime"
sed 's/inverter: {model/inverter: {dead_time_s: 1.5e-6, model/' scenarios/diagnose-bench.yaml >"$work/dt.yaml"
"$rpem" sim --scenario "$work/dt.yaml" --out "$work/dt.csv" --truth "$work/dt-truth.csv" >/dev/null 2>&1
"$rpem" diagnose --log "$work/dt.csv" --truth "$work/dt-truth.csv" --switching-frequency-Hz 4000 --out "$work/dt" 2>/dev/null
keep "$work/dt" deadtime

echo "== offnominal"
"$indep" --config config/paper-ipmsm.yaml --effects deadtime,delay --seed 7 --duration-s 20 \
  --set draw.psi_m_rel=-0.05 --set draw.r_s_rel=0.18 --set deadtime.t_dead_s=2e-6 --set delay.periods=2 \
  --out "$work/off.csv" --truth "$work/off-truth.json" >/dev/null
"$rpem" diagnose --log "$work/off.csv" --config config/paper-ipmsm.yaml --switching-frequency-Hz 8000 --out "$work/off" 2>/dev/null
keep "$work/off" offnominal
cp "$work/off-truth.json" "$figures/offnominal/truth.json"

echo "== paderborn"
python3 scripts/paderborn_to_drive_log.py data/paderborn-motor-temperature/profile_A_every5th.csv "$work/profile.csv" \
  --pole-pairs 4 --sample-period-s 2.5
"$rpem" diagnose --log "$work/profile.csv" --config config/paderborn-pmsm.yaml --out "$work/pb" 2>/dev/null
keep "$work/pb" paderborn

echo "== paderborn-judged"
# Rows 1..1760 (t < 4400 s): the heat-up at i_d ≈ −200 A; rows 1761.. : the cool-down at i_d ≈ −107 A.
head -n 1761 "$work/profile.csv" >"$work/heatup.csv"
{ head -n 1 "$work/profile.csv"; tail -n +1762 "$work/profile.csv"; } >"$work/cooldown.csv"
"$rpem" diagnose --log "$work/heatup.csv" --config config/paderborn-pmsm.yaml --out "$work/heatup" 2>/dev/null
"$rpem" diagnose --log "$work/cooldown.csv" --config config/paderborn-pmsm.yaml --out "$work/cool-plain" 2>/dev/null
"$rpem" diagnose --log "$work/cooldown.csv" --config "$work/heatup/extended.yaml" --out "$work/cool-extended" 2>/dev/null
keep "$work/heatup" paderborn-heatup
keep "$work/cool-plain" paderborn-cooldown-plain
keep "$work/cool-extended" paderborn-cooldown-extended

echo "== figures and reports in $figures"
