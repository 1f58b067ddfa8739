#!/usr/bin/env bash
# Cross-builds the whole project for ARM and runs every unit and mock integration test under
# qemu-user (docs/testing.md, "Cross builds").
#   scripts/cross-test.sh arm64|armhf
# On a Debian bookworm machine, as root: installs crossbuild-essential-<arch> and qemu-user-static,
# builds a sysroot of the target's libraries in build/sysroot-<arch>/ (the .debs are kept in
# build/cross-debs-<arch>/, so a rerun downloads nothing), configures build-<arch>/ with
# cmake/toolchains/<triplet>.cmake, builds everything but the benchmarks, runs ctest.
# Prints the time of each phase. JOBS (default: nproc) sets the parallelism.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

arch=${1:-}
case "$arch" in
  arm64) triplet=aarch64-linux-gnu ;;
  armhf) triplet=arm-linux-gnueabihf ;;
  *)
    echo "usage: scripts/cross-test.sh arm64|armhf" >&2
    exit 2
    ;;
esac
jobs=${JOBS:-$(nproc)}
sysroot=$root/build/sysroot-$arch
debs=$root/build/cross-debs-$arch
build=$root/build-$arch
export DEBIAN_FRONTEND=noninteractive

# The target's -dev packages, one per dependency in cmake/Dependencies.cmake (benchmarks are off).
dev_packages=(
  libboost-math-dev libtomlplusplus-dev libspdlog-dev libi2c-dev libgpiod-dev libsystemd-dev libgtest-dev
  libc6 libstdc++6 libgcc-s1
)
# Architecture-independent (header-only) packages: no :<arch> name, no library to follow.
header_only=(libeigen3-dev nlohmann-json3-dev libcli11-dev)
# The compiler, its headers and the target's libc headers come from crossbuild-essential
# (/usr/<triplet>); the sysroot's own copies would only shadow them.
not_in_sysroot='^(libc6-dev|linux-libc-dev|libstdc\+\+-12-dev|libgcc-12-dev|libcrypt-dev|libnsl-dev|libtirpc-dev|gcc-12-base|libc-dev-bin|rpcsvc-proto)$'

elapsed() { echo $(($(date +%s) - $1)); }

# A foreign index that fails to download (a mirror in sync: "File has unexpected size") leaves
# apt with the previous or the release's index, which is enough for a sysroot: go on.
update_indexes() {
  apt-get update -qq || echo "cross-test: apt-get update reported errors; using the indexes it has" >&2
}

install_host_tools() {
  local missing=()
  for p in crossbuild-essential-"$arch" qemu-user-static cmake pkg-config; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if ! dpkg --print-foreign-architectures | grep -qx "$arch"; then
    [ "$(id -u)" -eq 0 ] || { echo "cross-test: run as root to add the $arch architecture" >&2; exit 1; }
    dpkg --add-architecture "$arch"
    update_indexes
  fi
  if [ ${#missing[@]} -gt 0 ]; then
    [ "$(id -u)" -eq 0 ] || { echo "cross-test: run as root to install: ${missing[*]}" >&2; exit 1; }
    update_indexes
    apt-get install -y -qq --no-install-recommends "${missing[@]}"
  fi
}

# Every package the target needs at build and run time: the -dev packages and their Depends and
# Pre-Depends, followed level by level (no Recommends or Suggests), as names of this architecture.
# Dependencies on another architecture's packages (tools such as perl) are not libraries the
# target links, and the packages in $not_in_sysroot are neither kept nor followed.
resolve_packages() {
  local -A seen=()
  local level=("${dev_packages[@]}") next p
  while [ ${#level[@]} -gt 0 ]; do
    next=()
    for p in "${level[@]}"; do seen[$p]=1; done
    for p in $(apt-cache depends --no-recommends --no-suggests --no-conflicts --no-breaks --no-replaces \
      --no-enhances "${level[@]/%/:$arch}" | sed -n "s/^ *|\?\(Pre\)\?Depends: \([a-z0-9][a-z0-9.+-]*\):$arch\$/\2/p" |
      sort -u | grep -Ev "$not_in_sysroot"); do
      [ -n "${seen[$p]:-}" ] || next+=("$p")
    done
    level=("${next[@]}")
  done
  printf '%s\n' "${!seen[@]}" "${header_only[@]}" | sort -u
}

# resolve_packages, remembered until apt's indexes for this architecture change (resolving
# takes a minute or more on a loaded machine; a rerun should not).
cached_packages() {
  local indexes list=$debs/packages.list
  indexes=$(ls -l --time-style=+%s /var/lib/apt/lists/*_binary-"${arch}"_Packages* 2>/dev/null | sha256sum | cut -c1-16)
  if [ -f "$list" ] && [ "$(head -1 "$list")" = "# indexes $indexes" ]; then
    tail -n +2 "$list"
    return
  fi
  mkdir -p "$debs"
  { echo "# indexes $indexes"; resolve_packages; } >"$list.new"
  mv "$list.new" "$list"
  tail -n +2 "$list"
}

build_sysroot() {
  local packages stamp
  packages=$(cached_packages)
  stamp=$(echo "$packages" | sha256sum | cut -c1-16)
  if [ -f "$sysroot/.gyrod-packages-$stamp" ]; then
    echo "cross-test: sysroot $sysroot is up to date ($(echo "$packages" | wc -l) packages)"
    return
  fi
  mkdir -p "$debs"
  # apt-get download writes into the current folder and skips nothing: fetch only what is missing.
  local wanted=()
  for p in $packages; do
    compgen -G "$debs/${p}_*_${arch}.deb" >/dev/null || compgen -G "$debs/${p}_*_all.deb" >/dev/null ||
      wanted+=("$p")
  done
  if [ ${#wanted[@]} -gt 0 ]; then
    (cd "$debs" && apt-get download -qq -o APT::Architecture="$arch" "${wanted[@]}")
  fi
  rm -rf "$sysroot"
  mkdir -p "$sysroot"
  for p in $packages; do
    for deb in "$debs/${p}"_*_"$arch".deb "$debs/${p}"_*_all.deb; do
      [ -f "$deb" ] && dpkg -x "$deb" "$sysroot"
    done
  done
  touch "$sysroot/.gyrod-packages-$stamp"
  echo "cross-test: sysroot $sysroot: $(echo "$packages" | wc -l) packages"
}

t0=$(date +%s)
install_host_tools
build_sysroot
t_sysroot=$(elapsed "$t0")

t0=$(date +%s)
launcher=()
if [ -n "${CCACHE_DIR:-}" ] && command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B "$build" -DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchains/$triplet.cmake" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGYROD_BUILD_BENCHMARKS=OFF "${launcher[@]}" >/dev/null
cmake --build "$build" -j"$jobs" 2>&1 | tee "$build/build.log"
warnings=$(grep -c 'warning:' "$build/build.log" || true)
t_build=$(elapsed "$t0")

# Under qemu-user the tests take longer than natively: ctest gets a generous timeout per test,
# and the tests that need an emulator gap marked know it from GYROD_TEST_EMULATOR.
t0=$(date +%s)
status=0
GYROD_TEST_EMULATOR=qemu-user ctest --test-dir "$build" --output-on-failure -j"$jobs" --timeout 1200 |
  tee "$build/ctest.log" || status=$?
t_test=$(elapsed "$t0")

echo "cross-test $arch: sysroot ${t_sysroot}s, build ${t_build}s (${warnings} warnings), tests ${t_test}s"
grep -E 'tests passed|tests failed' "$build/ctest.log" || true
exit "$status"
