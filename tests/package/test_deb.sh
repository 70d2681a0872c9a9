#!/usr/bin/env bash
# The .deb on a clean Debian 12: debootstrap (minbase, cached as a tarball) → fresh root → apt install the
# package (dependencies from Debian) → the units (rpemd, rpem-can@, rpem-vcan@) verify and score ≤ 2.5 → rpemd runs from the
# installed configuration as an unprivileged user (the way the service runs it) and estimates.
#   test_deb.sh BUILD_DIR [--base]
# --base only makes the cached debootstrap (ctest's fixture package_deb_base: it runs beside other tests,
# while package_deb, whose rpemd shares the host's network, runs alone).
set -euo pipefail
build=$(cd "$1" && pwd)
cache=${RPEM_DEBOOTSTRAP_CACHE:-$build/debootstrap-cache}
mkdir -p "$cache"
base=$cache/bookworm-minbase.tar
if [[ ! -f $base ]]; then
  echo "test_deb: debootstrap bookworm (once, cached in $base)"
  tmp=$(mktemp -d)
  debootstrap --variant=minbase bookworm "$tmp" http://deb.debian.org/debian >"$cache/debootstrap.log" 2>&1 ||
    { tail -n 20 "$cache/debootstrap.log"; rm -rf "$tmp"; exit 1; }
  tar -C "$tmp" -cf "$base.part" .
  mv "$base.part" "$base"  # never a half-written cache
  rm -rf "$tmp"
fi
if [[ ${2:-} == --base ]]; then
  echo "test_deb: base ready: $base"
  exit 0
fi

# Packed under the strictest umask on purpose: the package's modes must not depend on the builder's.
(umask 077 && cd "$build" && cpack -G DEB >/dev/null)
deb=$(ls -t "$build"/rpem-drive_*_amd64.deb | head -n1)
root=$(mktemp -d)
cleanup() {
  for m in dev/pts dev proc sys; do umount "$root/$m" 2>/dev/null || true; done
  rm -rf "$root"
}
trap cleanup EXIT
tar -C "$root" -xf "$base"
chmod 0755 "$root"  # mktemp's 0700 (kept by tar for ".") would shut the unprivileged run out of /
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount -t proc proc "$root/proc"
mount -t sysfs sys "$root/sys"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"
cp "$deb" "$root/tmp/"
in_root() { chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root "$@"; }

echo "test_deb: installing $(basename "$deb") into a clean Debian 12"
in_root apt-get update -q >/dev/null
DEBIAN_FRONTEND=noninteractive in_root apt-get install -y -q --no-install-recommends "/tmp/$(basename "$deb")" >"$root/tmp/apt.log" 2>&1 ||
  { cat "$root/tmp/apt.log"; exit 1; }
in_root dpkg -s rpem-drive | grep -q "Status: install ok installed"
[[ -L $root/etc/systemd/system/multi-user.target.wants/rpemd.service ]] || { echo "test_deb: rpemd.service not enabled"; exit 1; }

echo "test_deb: checking the installed units (rpemd and the bus bring-up units): verify clean, exposure <= 2.5"
for unit in rpemd.service rpemd@.service rpem-can@.service rpem-vcan@.service; do
  path=/usr/lib/systemd/system/$unit
  [[ -f $root$path ]] || { echo "test_deb: $unit not installed"; exit 1; }
  # verify exits 0 on unknown keys and bad values too: anything it says about the unit is a failure.
  said=$(in_root systemd-analyze verify "$path" 2>&1 | grep -F "${unit%%@*}" || true)
  [[ -z $said ]] || { echo "test_deb: systemd-analyze verify $unit:"; echo "$said"; exit 1; }
  score=$(in_root systemd-analyze security --offline=yes "$path" 2>&1 | awk '/Overall exposure level/{print $(NF-2)}')
  echo "test_deb: $unit exposure $score"
  awk -v s="$score" 'BEGIN { exit !(s != "" && s <= 2.5) }' || { echo "test_deb: $unit exposure '$score' > 2.5"; exit 1; }
done

echo "test_deb: running the installed rpemd with the installed configuration, as an unprivileged user with"
echo "          the unit's LimitRTPRIO=90 and LimitMEMLOCK=infinity (so SCHED_FIFO and mlockall need no root)"
in_root /usr/sbin/rpemd --config /etc/rpemd/rpemd.yaml --check-config
in_root mkdir -p /var/lib/rpemd && in_root chown nobody:nogroup /var/lib/rpemd
limits=(prlimit --rtprio=90 --memlock=unlimited)
if ! in_root "${limits[@]}" true 2>/dev/null; then
  echo "test_deb: note: this sandbox cannot raise RLIMIT_RTPRIO/MEMLOCK (no CAP_SYS_RESOURCE); running best effort"
  limits=()
fi
set +e
in_root "${limits[@]}" setpriv --reuid=nobody --regid=nogroup --clear-groups \
  /usr/bin/env STATE_DIRECTORY=/var/lib/rpemd \
  timeout -s TERM 25 /usr/sbin/rpemd --config /etc/rpemd/rpemd.yaml >"$root/tmp/rpemd.out" 2>&1
rc=$?
set -e
cat "$root/tmp/rpemd.out"
[[ $rc -eq 124 || $rc -eq 0 ]] || { echo "test_deb: rpemd exited with $rc"; exit 1; }
grep -q "rpemd running" "$root/tmp/rpemd.out" || { echo "test_deb: no estimates"; exit 1; }
if [[ ${#limits[@]} -gt 0 ]] && grep -q "warning" "$root/tmp/rpemd.out"; then
  echo "test_deb: real-time set-up incomplete under the unit's limits"; exit 1
fi
grep -q "rpemd: stopped" "$root/tmp/rpemd.out" || { echo "test_deb: no clean stop on SIGTERM"; exit 1; }
[[ -f $root/var/lib/rpemd/estimates.json ]] || { echo "test_deb: no state file written at shutdown"; exit 1; }
in_root /usr/bin/rpem --help >/dev/null

echo "test_deb: the copyright file and the data the shipped scenarios use"
copyright=$root/usr/share/doc/rpem-drive/copyright
[[ -f $copyright ]] || { echo "test_deb: no /usr/share/doc/rpem-drive/copyright"; exit 1; }
grep -q '^Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/' "$copyright" ||
  { echo "test_deb: copyright is not in Debian's machine-readable format"; exit 1; }
for set in "$(dirname "$0")"/../../data/*/; do
  name=$(basename "$set")
  grep -q "^Files: data/$name/\*" "$copyright" || { echo "test_deb: copyright does not name data set $name"; exit 1; }
  (cd "$root/usr/share/rpem-drive/data/$name" && sha256sum --check --strict --quiet SHA256SUMS) ||
    { echo "test_deb: installed data set $name missing or changed"; exit 1; }
done
in_root /usr/bin/rpem sim --scenario /usr/share/rpem-drive/scenarios/diagnose-beckhoff.yaml --out /tmp/beckhoff.csv >/dev/null 2>&1 ||
  { echo "test_deb: the installed diagnose-beckhoff scenario does not run (its flux map or machine not found?)"; exit 1; }
echo "test_deb: passed"
