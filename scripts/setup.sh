#!/usr/bin/env bash
# Installs every build, test and runtime dependency of rpem-drive from Debian 12 packages.
# Idempotent: packages already present are skipped, so a second run is quick and changes nothing.
set -euo pipefail

packages=(
  # toolchain and build
  build-essential cmake ninja-build pkg-config git
  # libraries
  libeigen3-dev libyaml-cpp-dev libceres-dev libcli11-dev nlohmann-json3-dev libsystemd-dev
  # message authentication (HMAC-SHA256) of rpemd's LCM channels
  libsodium-dev
  # LCM (C++ headers, lcm-gen, Java jar for lcm-spy) and lcm-spy's chart library
  liblcm-dev liblcm-bin liblcm-java libjchart2d-java default-jdk-headless
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev rt-tests
  # the format and lint gates (scripts/lint.py)
  clang-format clang-tidy
  # plots
  gnuplot-nox
  # CAN tooling and the PREEMPT_RT VM test rig (qemu, busybox initramfs)
  can-utils iproute2 qemu-system-x86 busybox-static cpio kmod xz-utils zstd
  # systemd-analyze for unit verification; dpkg-deb for the .deb package
  systemd dpkg-dev fakeroot debootstrap
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo_cmd=()
  [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -q
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#packages[@]} packages present" >&2
fi
