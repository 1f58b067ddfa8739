#!/usr/bin/env bash
# The ARM tier for .ci/run (as root on Debian bookworm): for each architecture, the cross build
# and the whole suite under qemu-user (scripts/cross-test.sh ARCH), then its .deb
# (scripts/package.sh ARCH: the hardening checked on the ARM binaries) and lintian on it.
#   scripts/ci-arm.sh [ARCH...]        default: $GYROD_CI_ARM, else "arm64 armhf"
# Each architecture prints its phases' times (sysroot, build, tests) and its total; the last line
# is the tier's total. docs/testing.md ("Cross builds") gives the measured times and what each
# architecture finds: armhf is the 32-bit one (size_t, long and time_t of 32 bits), where this
# tier found its bugs; arm64 is the 64-bit OS of a Pi 3/4/5.
set -euo pipefail
cd "$(dirname "$0")/.."
read -r -a arches <<<"${*:-${GYROD_CI_ARM:-arm64 armhf}}"
tier_start=$(date +%s)
for arch in "${arches[@]}"; do
  case $arch in
    arm64 | armhf) ;;
    *)
      echo "ci-arm: unknown architecture '$arch' (arm64 or armhf)" >&2
      exit 2
      ;;
  esac
  t0=$(date +%s)
  scripts/cross-test.sh "$arch"
  deb=$(scripts/package.sh "$arch")
  if command -v lintian >/dev/null 2>&1; then
    lintian --fail-on error,warning "$deb"
  fi
  echo "ci-arm: $arch: suite passed, $deb built, in $(($(date +%s) - t0)) s"
done
echo "ci-arm: ${arches[*]} in $(($(date +%s) - tier_start)) s"
