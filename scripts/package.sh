#!/usr/bin/env bash
# Builds the Debian package of gyrod for one architecture:
#   scripts/package.sh amd64|arm64|armhf   ->   build/deb/gyrod_<version>_<arch>.deb
# <version> is the project's CMake version (project(gyrod VERSION ...)).
#
# How: `cmake --install --strip` with DESTDIR into a staging tree, plus the files of
# packaging/debian/, then `dpkg-deb --root-owner-group --build`. Chosen over CPack's DEB generator
# because the control file, conffiles and maintainer scripts stay plain files a reader and lintian
# see as they are; CPack would need the same files (CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA) and more.
#
# Build trees: amd64 uses build/ (the README's; configured here with tests off when absent, or
# $GYROD_BUILD_DIR); arm64 and armhf use build-arm64/ and build-armhf/, made by
# `scripts/cross-test.sh ARCH`, and this script stops when they are absent. The tree is
# reconfigured with the Debian install paths (prefix /usr, /etc, units in /lib/systemd/system as
# on bookworm), which changes no compiled file, and only gyrod and gyroctl are (re)built.
# It also turns GYROD_HARDENING on (the default) in a tree configured without it: that tree is
# then rebuilt once.
# The same tree and SOURCE_DATE_EPOCH give the same .deb, byte for byte.
# Needs: cmake, binutils (readelf, objcopy), gzip; dpkg-dev when present (dpkg-shlibdeps).
# Environment: GYROD_DEB_MAINTAINER ("Name <address>"), SOURCE_DATE_EPOCH (file times and the
# changelog's date; default: the last commit's time), GYROD_DEB_CROSS_DEPENDS=1 (work out Depends
# as for a cross build, to compare it with dpkg-shlibdeps's).
set -euo pipefail
cd "$(dirname "$0")/.."

die() {
  echo "package.sh: $*" >&2
  exit 1
}

arch=${1:-}
case $arch in
  amd64) elf_machine='Advanced Micro Devices X86-64' ;;
  arm64) elf_machine=AArch64 ;;
  armhf) elf_machine=ARM ;;
  *) die "usage: scripts/package.sh amd64|arm64|armhf (got '${arch}')" ;;
esac

version=$(sed -nE 's/^project\(gyrod VERSION ([0-9][0-9A-Za-z.+~]*).*/\1/p' CMakeLists.txt)
[ -n "$version" ] || die "no 'project(gyrod VERSION x.y.z ...)' line in CMakeLists.txt"
maintainer=${GYROD_DEB_MAINTAINER:-gyrod maintainers <gyrod-maintainers@users.noreply.github.com>}
if [ -z "${SOURCE_DATE_EPOCH:-}" ]; then
  SOURCE_DATE_EPOCH=$(git log -1 --format=%ct 2>/dev/null || date +%s)
fi
export SOURCE_DATE_EPOCH

if [ "$arch" = amd64 ]; then
  build_dir=${GYROD_BUILD_DIR:-build}
  if [ ! -f "$build_dir/CMakeCache.txt" ]; then
    echo "package.sh: configuring $build_dir (tests and benchmarks off)"
    cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGYROD_BUILD_TESTS=OFF \
      -DGYROD_BUILD_BENCHMARKS=OFF >/dev/null
  fi
else
  build_dir=build-$arch
  [ -f "$build_dir/CMakeCache.txt" ] ||
    die "$build_dir/ is not a configured build tree: run scripts/cross-test.sh $arch first (it cross-builds into $build_dir/)"
fi
if grep -qE '^GYROD_SANITIZE:BOOL=(ON|TRUE|1)$' "$build_dir/CMakeCache.txt"; then
  die "$build_dir/ is a sanitizer build (GYROD_SANITIZE=ON): package a plain build"
fi

# The Debian layout of bookworm: units and udev rules under /lib (where debhelper puts them),
# sysusers.d under /usr/lib.
# With Debian's hardening flags (cmake/Hardening.cmake), checked on the staged binaries below as
# lintian would.
cmake -S . -B "$build_dir" -DCMAKE_INSTALL_PREFIX=/usr -DGYROD_HARDENING=ON \
  -DGYROD_SYSTEMD_UNIT_DIR=/lib/systemd/system -DGYROD_UDEV_RULES_DIR=/lib/udev/rules.d \
  -DGYROD_SYSUSERS_DIR=/usr/lib/sysusers.d >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target gyrod gyroctl >/dev/null

for binary in gyrod gyroctl; do
  machine=$(readelf -h "$build_dir/bin/$binary" | sed -nE 's/^ *Machine: *//p')
  [ "$machine" = "$elf_machine" ] || die "$build_dir/bin/$binary is built for '$machine', not $arch ($elf_machine)"
done

out_dir=build/deb
work=$out_dir/work-$arch
root=$work/debian/gyrod # dpkg-shlibdeps expects the binaries under debian/<package>/
rm -rf "$work"
mkdir -p "$root" "$out_dir"
umask 022
DESTDIR=$PWD/$root cmake --install "$build_dir" --strip >/dev/null
# As dh_strip: also drop the compiler's .comment and .note sections (the toolchain's objcopy).
objcopy=$(sed -n 's/^CMAKE_OBJCOPY:FILEPATH=//p' "$build_dir/CMakeCache.txt")
for binary in "$root/usr/sbin/gyrod" "$root/usr/bin/gyroctl"; do
  "${objcopy:-objcopy}" --remove-section=.comment --remove-section=.note "$binary"
done

tests/packaging/check-hardening.sh "$root/usr/sbin/gyrod" "$root/usr/bin/gyroctl" >/dev/null ||
  die "the binaries lack Debian's hardening (above)"

doc=$root/usr/share/doc/gyrod
mkdir -p "$doc" "$root/DEBIAN"
copyright=$(sed -nE 's/^Copyright \(c\) //p' LICENSE)
sed -e "s|@MAINTAINER@|$maintainer|" -e "s|@COPYRIGHT@|$copyright|" packaging/debian/copyright.in >"$doc/copyright"
# The licence text as a DEP-5 paragraph: indented, blank lines as " .".
sed -n '/^Permission is hereby granted/,$p' LICENSE | sed 's/^$/./; s/^/ /' >>"$doc/copyright"
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
{
  echo "gyrod ($version) unstable; urgency=medium"
  echo
  echo "  * Built from the gyrod sources (commit $commit) by scripts/package.sh."
  echo
  echo " -- $maintainer  $(LC_ALL=C date -u -R -d "@$SOURCE_DATE_EPOCH")"
} | gzip -9n >"$doc/changelog.gz"
# Debian compresses man pages (dh_compress does the same).
find "$root/usr/share/man" -type f -name '*.[0-9]' -exec gzip -9n {} +

# Depends: from the binaries' shared libraries. Natively dpkg-shlibdeps works them out; for a
# cross build, cross_depends (scripts/deb-depends.sh) does.
# shellcheck source=scripts/deb-depends.sh
. scripts/deb-depends.sh
binaries=("$root/usr/sbin/gyrod" "$root/usr/bin/gyroctl")
# dpkg-shlibdeps is in dpkg-dev, which a machine set up by scripts/install-deps.sh may lack.
if [ "$arch" = "$(dpkg --print-architecture)" ] && [ -z "${GYROD_DEB_CROSS_DEPENDS:-}" ] &&
  command -v dpkg-shlibdeps >/dev/null 2>&1; then
  mkdir -p "$work/debian"
  echo "Source: gyrod" >"$work/debian/control"
  shlibs=$(cd "$work" && dpkg-shlibdeps -O "${binaries[@]/#$work\//-e}" 2>/dev/null | sed -n 's/^shlibs:Depends=//p')
else
  sonames=$(for binary in "${binaries[@]}"; do readelf -d "$binary"; done | sed -nE 's/.*\(NEEDED\).*\[(.*)\]/\1/p' | sort -u)
  shlibs=$(for soname in $sonames; do cross_depends "$soname"; done | sort -u | paste -sd, | sed 's/,/, /g')
fi
[ -n "$shlibs" ] || die "could not work out the shared-library dependencies of gyrod and gyroctl"

installed_size=$(du -sk --apparent-size --exclude=DEBIAN "$root" | cut -f1)
sed -e "s|@VERSION@|$version|" -e "s|@ARCH@|$arch|" -e "s|@MAINTAINER@|$maintainer|" \
  -e "s|@INSTALLED_SIZE@|$installed_size|" -e "s|@SHLIBS_DEPENDS@|$shlibs|" \
  packaging/debian/control.in >"$root/DEBIAN/control"
cp packaging/debian/conffiles "$root/DEBIAN/conffiles"
mkdir -p "$root/usr/share/lintian/overrides"
cp packaging/debian/lintian-overrides "$root/usr/share/lintian/overrides/gyrod"
install -m 0755 packaging/debian/postinst packaging/debian/prerm packaging/debian/postrm "$root/DEBIAN/"
while read -r conffile; do
  [ -f "$root$conffile" ] || die "conffile $conffile is not in the package (cmake --install did not install it)"
done <"$root/DEBIAN/conffiles"
(cd "$root" && find . -path ./DEBIAN -prune -o -type f -printf '%P\0' | LC_ALL=C sort -z | xargs -0 md5sum) \
  >"$root/DEBIAN/md5sums"

# Reproducible file modes and times.
find "$root" -type d -exec chmod 0755 {} +
find "$root" -type f ! -path "*/DEBIAN/*" ! -path '*/bin/*' ! -path '*/sbin/*' -exec chmod 0644 {} +
find "$root" -newermt "@$SOURCE_DATE_EPOCH" -exec touch -h -d "@$SOURCE_DATE_EPOCH" {} +

deb=$out_dir/gyrod_${version}_${arch}.deb
dpkg-deb --root-owner-group -Zxz --build "$root" "$deb" >/dev/null
echo "$deb"
