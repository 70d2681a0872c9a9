#!/bin/sh
# The bus bring-up units' own commands under the units' own credentials, on real interfaces: what
# rpem-vcan@.service and rpem-can@.service grant is an unprivileged user with CAP_NET_ADMIN as its only
# capability (bounding set and ambient) and no new privileges. Each Exec line is read from the unit
# file with %i replaced. Runs as root where the interfaces can be made (the VM; natively with vcan).
#   bus_units.sh UNIT_DIR
# vcan: rpem-vcan@vcan7's ExecStartPre/ExecStart make vcan7 (CAN FD MTU, up), ExecStop removes it;
#       without CAP_NET_ADMIN the same command is refused (the check is not vacuous).
# can:  where a CAN controller exists (can0: the VM's emulated Kvaser PCI, an SJA1000 — classic CAN
#       only): rpem-can@can0's ExecStartPre, then its ExecStart, which the controller refuses only for
#       the CAN FD part (not supported, rather than not permitted), then the same line without it brings
#       can0 up at 1 Mbit/s with restart-ms 100; ExecStop brings it down.
units=${1:-.}
fail=0
# Absolute paths: the VM's busybox shell would run its own applets of these names first.
ip=/sbin/ip
setpriv=/usr/bin/setpriv
[ -x "$units/setpriv" ] && setpriv=$units/setpriv
say() { echo "bus_units: $*"; }
as_unit() { "$setpriv" --reuid=65534 --regid=65534 --clear-groups --no-new-privs --bounding-set=-all,+net_admin \
              --inh-caps=-all,+net_admin --ambient-caps=-all,+net_admin "$@"; }
without_caps() { "$setpriv" --reuid=65534 --regid=65534 --clear-groups --no-new-privs --bounding-set=-all \
                   --inh-caps=-all --ambient-caps=-all "$@"; }
# exec_lines UNIT KEY INSTANCE: the commands of that key, without systemd's "-" prefix.
exec_lines() { sed -n "s/^$2=-\{0,1\}//p" "$units/$1" | sed "s/%i/$3/g"; }
run_lines() {  # UNIT KEY INSTANCE: each as the unit would run it; 1 if any fails
  exec_lines "$1" "$2" "$3" | while read -r cmd; do
    say "  $2: $cmd"
    as_unit $cmd || exit 1
  done
}

say "vcan: rpem-vcan@vcan7 as the unit runs it"
run_lines rpem-vcan@.service ExecStartPre vcan7 || { say "FAIL ExecStartPre"; fail=1; }
run_lines rpem-vcan@.service ExecStart vcan7 || { say "FAIL ExecStart"; fail=1; }
if $ip -details link show vcan7 | grep -q "mtu 72.*UP\|UP.*mtu 72"; then say "ok    vcan7 is up with the CAN FD MTU"; else say "FAIL vcan7 not up"; $ip -details link show vcan7; fail=1; fi
run_lines rpem-vcan@.service ExecStop vcan7 || { say "FAIL ExecStop"; fail=1; }
if $ip link show vcan7 >/dev/null 2>&1; then say "FAIL vcan7 still exists"; fail=1; else say "ok    ExecStop removed vcan7"; fi
if without_caps $ip link add dev vcan8 type vcan 2>/dev/null; then
  say "FAIL without CAP_NET_ADMIN vcan8 was made: the check proves nothing"; $ip link del vcan8; fail=1
else
  say "ok    without CAP_NET_ADMIN the same command is refused"
fi

if $ip link show can0 >/dev/null 2>&1; then
  say "can: rpem-can@can0 as the unit runs it (emulated SJA1000: classic CAN only)"
  run_lines rpem-can@.service ExecStartPre can0 || { say "FAIL ExecStartPre"; fail=1; }
  start=$(exec_lines rpem-can@.service ExecStart can0)
  why=$(as_unit $start 2>&1)
  case $why in
    *"not supported"*|*"Not supported"*) say "ok    ExecStart refused only for what the controller lacks: $why" ;;
    "") say "ok    ExecStart succeeded (a CAN FD controller)" ;;
    *) say "FAIL ExecStart: $why"; fail=1 ;;
  esac
  classic=$(echo "$start" | sed 's/ dbitrate [0-9]*//; s/ fd on//')
  say "  the same without CAN FD: $classic"
  as_unit $classic || { say "FAIL $classic"; fail=1; }
  details=$($ip -details link show can0)
  if echo "$details" | grep -q "bitrate 1000000" && echo "$details" | grep -q "restart-ms 100" &&
     echo "$details" | grep -q "state UP\|,UP"; then
    say "ok    can0 is up at 1 Mbit/s with restart-ms 100"
  else
    say "FAIL can0: $details"; fail=1
  fi
  run_lines rpem-can@.service ExecStop can0 || { say "FAIL ExecStop"; fail=1; }
  if $ip link show can0 | grep -q "state DOWN\|<NOARP>\|<NOARP,ECHO>"; then say "ok    ExecStop brought can0 down"; else say "FAIL can0 still up"; $ip link show can0; fail=1; fi
else
  say "can: no CAN controller here; skipped"
fi
say "$([ $fail -eq 0 ] && echo passed || echo failed)"
exit $fail
