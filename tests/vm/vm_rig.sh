#!/usr/bin/env bash
# The vcan test rig: runs a command inside a VM that boots Debian's PREEMPT_RT kernel under qemu
# (TCG) with vcan0 up in CAN FD mode and multicast on loopback (for LCM). Used where the host kernel
# has no vcan/AF_CAN; on a host that has them the tests run natively (tests/vm/run_*_suite.sh, `vm_rig.sh native-vcan`).
#
#   vm_rig.sh native-vcan    (exit 0: run natively, the host has vcan0)
#   vm_rig.sh run [--timeout S] [--smp N] [--share DIR] [--can-controller] [--file SRC[:DEST]]... -- COMMAND...
#
# --can-controller adds an emulated CAN controller (qemu's Kvaser PCI, an SJA1000: classic CAN) as can0,
# on a virtual bus of its own.
# Every ELF given with --file (and busybox, iproute2's ip, can-utils, cyclictest) is copied into an
# initramfs with the shared libraries ldd names. --share mounts a host directory at /host (virtio-9p)
# for inputs and results. The command runs in /work; its exit code becomes this script's.
# The kernel package is fetched with apt-get download into $RPEM_VM_CACHE (default build/vm-cache).
# RPEM_VM_KERNEL_ARGS is appended to the guest kernel's command line (e.g. `tsc=reliable`: the guest otherwise
# picks the HPET clocksource, an emulated MMIO device, and does not offer the TSC).
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
cache=${RPEM_VM_CACHE:-$repo/build/vm-cache}

log() { echo "vm_rig: $*" >&2; }

prepare_kernel() {
  mkdir -p "$cache"
  if [[ -f $cache/kernel.ready ]]; then return; fi
  local pkg
  pkg=$(apt-cache depends linux-image-rt-amd64 | awk '/Depends: linux-image-[0-9]/{print $2; exit}')
  [[ -n $pkg ]] || { log "cannot resolve linux-image-rt-amd64"; exit 2; }
  log "fetching $pkg"
  (cd "$cache" && rm -f ./*.deb && apt-get download "$pkg" >/dev/null 2>&1)
  rm -rf "$cache/root"
  dpkg -x "$cache"/"$pkg"_*.deb "$cache/root"
  echo "$pkg" >"$cache/kernel.ready"
}

kernel_release() { ls "$cache/root/lib/modules" | head -n1; }

# copy_elf BIN DEST_DIR_IN_STAGE: the binary plus its shared libraries (and the loader).
copy_elf() {
  local src=$1 dest=$2
  mkdir -p "$stage$dest"
  cp -L "$src" "$stage$dest/"
  ldd "$src" 2>/dev/null | awk '/=> \//{print $3} /^\t\/lib/{print $1}' | while read -r lib; do
    mkdir -p "$stage$(dirname "$lib")"
    [[ -e $stage$lib ]] || cp -L "$lib" "$stage$lib"
  done
}

build_initramfs() {
  local out=$1
  shift
  umask 022  # the VM's unprivileged processes (tests/vm/bus_units.sh) must read its libraries
  stage=$(mktemp -d)
  chmod 0755 "$stage"
  trap 'rm -rf "$stage"' RETURN
  mkdir -p "$stage"/{bin,sbin,proc,sys,dev,tmp,run,etc,modules,work,var/lib/rpemd}
  cp /bin/busybox "$stage/bin/busybox"
  for applet in sh mount mkdir insmod poweroff echo cat sleep ls grep ps kill timeout dmesg sync ifconfig \
                  uname seq head tail wc date sed awk rm cp mv chmod killall pidof env nproc taskset free; do
    ln -sf busybox "$stage/bin/$applet"
  done
  copy_elf "$(command -v ip)" /sbin
  for tool in candump cansend canplayer cangen cyclictest; do
    if command -v "$tool" >/dev/null; then copy_elf "$(command -v "$tool")" /bin; fi
  done
  # Kernel modules and their dependencies, in load order.
  local release moddir
  release=$(kernel_release)
  moddir=$cache/root/lib/modules/$release/kernel
  : >"$stage/modules/order"
  add_module() {
    local name=$1 path dep
    grep -qx "$name" "$stage/modules/order" && return
    path=$(find "$moddir" -name "$name.ko" | head -n1)
    [[ -n $path ]] || { log "module $name not found"; exit 2; }
    for dep in $(/sbin/modinfo -F depends "$path" | tr ',' ' '); do add_module "$dep"; done
    cp "$path" "$stage/modules/"
    echo "$name" >>"$stage/modules/order"
  }
  for m in can-dev can can-raw vcan virtio_pci 9pnet_virtio 9p kvaser_pci; do add_module "$m"; done
  for spec in "${files[@]}"; do
    local src=${spec%%:*} dest=${spec#*:}
    [[ $spec == *:* ]] || dest=/work/$(basename "$src")
    if [[ $(head -c 4 "$src" | tail -c 3) == ELF ]]; then
      copy_elf "$src" "$(dirname "$dest")"
      [[ $(basename "$src") == $(basename "$dest") ]] || mv "$stage$(dirname "$dest")/$(basename "$src")" "$stage$dest"
    else
      mkdir -p "$stage$(dirname "$dest")"
      cp -rL "$src" "$stage$dest"
    fi
  done
  printf '%s\n' "${command[*]}" >"$stage/command"
  cat >"$stage/init" <<'INIT'
#!/bin/sh
export PATH=/work:/sbin:/bin
mount -t proc proc /proc; mount -t sysfs sys /sys; mount -t devtmpfs dev /dev; mount -t tmpfs tmp /tmp
for m in $(cat /modules/order); do insmod /modules/$m.ko || echo "vm: insmod $m failed"; done
mkdir -p /host && mount -t 9p -o trans=virtio,version=9p2000.L,msize=262144 host0 /host 2>/dev/null
ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo
ip link add dev vcan0 type vcan && ip link set vcan0 mtu 72 && ip link set vcan0 up
echo "vm: kernel $(uname -r), $(nproc) cpus; vcan0 $(cat /sys/class/net/vcan0/mtu 2>/dev/null) mtu"
cd /work
sh -c "$(cat /command)"
echo "RPEM_VM_EXIT=$?"
sync
poweroff -f
INIT
  chmod +x "$stage/init"
  (cd "$stage" && find . | cpio -o -H newc --quiet | gzip -1) >"$out"
}

run() {
  local timeout=600 smp=2 share="" can_args=()
  files=()
  while [[ $# -gt 0 ]]; do
    case $1 in
      --timeout) timeout=$2; shift 2 ;;
      --smp) smp=$2; shift 2 ;;
      --file) files+=("$2"); shift 2 ;;
      --share) share=$(cd "$2" && pwd); shift 2 ;;
      --can-controller) can_args=(-object can-bus,id=canbus0 -device kvaser_pci,canbus=canbus0); shift ;;
      --) shift; break ;;
      *) log "unknown option $1"; exit 2 ;;
    esac
  done
  command=("$@")
  prepare_kernel
  local initrd console
  initrd=$(mktemp --suffix=.gz)
  console=$(mktemp)
  # Expanded now: a signal (ctest's timeout) runs the trap where these locals are out of scope.
  trap "rm -f $(printf %q "$initrd") $(printf %q "$console")" EXIT
  build_initramfs "$initrd"
  log "booting $(cat "$cache/kernel.ready") (TCG, $smp cpus${RPEM_VM_KERNEL_ARGS:+; kernel args: $RPEM_VM_KERNEL_ARGS}) for: ${command[*]}"
  local vmlinuz
  vmlinuz=$(ls "$cache"/root/boot/vmlinuz-*)
  local share_args=()
  if [[ -n $share ]]; then
    share_args=(-virtfs "local,path=$share,mount_tag=host0,security_model=none,id=host0")
  fi
  set +e
  timeout --foreground "$timeout" qemu-system-x86_64 -accel tcg -cpu max -smp "$smp" -m 1G -nographic -no-reboot \
    "${share_args[@]}" "${can_args[@]}" -kernel "$vmlinuz" -initrd "$initrd" -append "console=ttyS0 quiet panic=-1 rdinit=/init${RPEM_VM_KERNEL_ARGS:+ $RPEM_VM_KERNEL_ARGS}" \
    </dev/null >"$console" 2>&1
  local qemu_rc=$?
  set -e
  # Show the VM's console from our init's first line on, without kernel messages.
  tr -d '\r' <"$console" | sed -n '/vm: kernel/,$p' | sed 's/^.*vm: kernel/vm: kernel/' | grep -v -E '^\[ *[0-9]+\.[0-9]+\]' || true
  local rc
  rc=$(grep -a -o 'RPEM_VM_EXIT=[0-9]*' "$console" | tail -n1 | cut -d= -f2)
  if [[ -z $rc ]]; then
    log "the VM did not report an exit code (qemu exit $qemu_rc; 124 = timeout)"
    exit 3
  fi
  exit "$rc"
}

# native-vcan: exit 0 where the tests can run natively instead (root, the kernel has vcan, vcan0 is up).
native_vcan() {
  [[ $(id -u) -eq 0 ]] && ip link add dev rpemprobe0 type vcan 2>/dev/null && ip link del rpemprobe0 &&
    ip link show vcan0 >/dev/null 2>&1
}

case ${1:-} in
  run) shift; run "$@" ;;
  native-vcan) native_vcan ;;
  prepare) prepare_kernel ;;
  *) echo "usage: $0 run [--timeout S] [--smp N] [--file SRC[:DEST]]... -- COMMAND..." >&2; exit 2 ;;
esac
