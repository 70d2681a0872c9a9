#!/usr/bin/env bash
# rpem diagnose on long recordings (issue 26; docs/benchmarks.md, "rpem diagnose on long recordings"): logs of
# the independent generator in the diagnose profile (8 kHz, dead time 2 µs) of each DURATION, diagnosed one
# after the other with each JOBS, under /usr/bin/time. Prints per run user, system and wall time, peak RSS,
# RSS and user time per sample, and the load average before it; then each JOBS' user time per sample against
# the mean over the durations (issue 26: within ±20 %). Logs are kept in WORK (1 GB for 10 minutes).
#   diagnose_long_logs.sh BUILD_DIR [WORK] [DURATIONS (default "20 80 320")] [JOBS (default "1 2")]
set -euo pipefail
build=$(cd "$1" && pwd)
work=${2:-/tmp/rpem_long_logs}
durations=${3:-20 80 320}
jobs=${4:-1 2}
repo=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
printf '| log | samples | jobs | user | sys | wall | peak RSS | RSS per sample | user per sample | load before |\n'
printf '|---|---|---|---|---|---|---|---|---|---|\n'
declare -A per_sample
for d in $durations; do
  log=$work/log$d.csv
  if [ ! -s "$log" ]; then
    "$build/tests/independent_drive/indep_drive_log" --config "$repo/config/paper-ipmsm.yaml" --effects deadtime \
      --set deadtime.t_dead_s=2e-6 --duration-s "$d" --out "$log" >/dev/null
  fi
  samples=$(($(wc -l <"$log") - 1))
  for j in $jobs; do
    load=$(cut -d' ' -f1 /proc/loadavg)
    /usr/bin/time -f '%U %S %e %M' -o "$work/time" "$build/tools/rpem" diagnose --log "$log" \
      --config "$repo/config/paper-ipmsm.yaml" --out "$work/out$d-$j" --jobs "$j" >"$work/out$d-$j.txt" 2>/dev/null
    read -r user sys wall rss_kB <"$work/time"
    per_sample[$d,$j]=$(awk -v u="$user" -v n="$samples" 'BEGIN { printf "%.2f", 1e6 * u / n }')
    awk -v d="$d" -v n="$samples" -v j="$j" -v u="$user" -v s="$sys" -v w="$wall" -v r="$rss_kB" -v l="$load" 'BEGIN {
      printf "| %s s | %d | %s | %.2f s | %.2f s | %.1f s | %.1f MB | %.0f B | %.1f µs | %s |\n",
             d, n, j, u, s, w, r / 1024, 1024 * r / n, 1e6 * u / n, l }'
  done
done
for j in $jobs; do
  values=""
  for d in $durations; do values="$values ${per_sample[$d,$j]}"; done
  echo "$values" | awk -v j="$j" '{ m = 0; for (i = 1; i <= NF; ++i) m += $i; m /= NF; w = 0;
    for (i = 1; i <= NF; ++i) { e = ($i - m) / m; if (e < 0) e = -e; if (e > w) w = e }
    printf "jobs %s: user per sample %s µs, mean %.2f, largest deviation %.0f %% (%s)\n", j, $0, m, 100 * w, w <= 0.2 ? "within ±20 %" : "OUTSIDE ±20 %" }'
done
