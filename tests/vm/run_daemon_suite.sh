#!/usr/bin/env bash
# ctest entry (label vcan): rpemd end to end over vcan0 with LCM — natively where the host has vcan,
# else in the PREEMPT_RT VM — then the host checks the results (check_daemon_suite.py).
#   run_daemon_suite.sh BUILD_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
files=("$build/tools/rpem" "$build/daemon/rpemd" "$here/daemon_suite.sh" "$here/rpemd-vcan.yaml"
       "$repo/scenarios/e2e-steps.yaml" "$repo/scenarios/e2e-steady.yaml")
if "$here/vm_rig.sh" native-vcan; then
  echo "run_daemon_suite: native vcan0"
  work=$(mktemp -d)
  cp "${files[@]}" "$work/"
  (cd "$work" && PATH="$work:$PATH" sh daemon_suite.sh "$out")
else
  echo "run_daemon_suite: no vcan on this host; running in the PREEMPT_RT VM"
  args=()
  for f in "${files[@]}"; do args+=(--file "$f"); done
  "$here/vm_rig.sh" run --timeout 1500 --share "$out" "${args[@]}" -- 'sh /work/daemon_suite.sh /host'
fi
python3 "$here/check_daemon_suite.py" "$out"
