# shellcheck shell=bash
# cross_depends SONAME: the Depends entry of a shared library, for a .deb whose binaries were
# cross-built (scripts/package.sh; tests/packaging/check-cross-depends.sh). The target's
# libraries are not in this machine's dpkg database, so each library is looked up in the shlibs
# file of the package that owns the host's copy of it: one Debian release ships the same
# library packages, with the same shlibs, on every architecture. With no such package it prints
# why and exits the (sub)shell it runs in with status 1.
cross_depends() {
  local soname=$1 multiarch owner name soversion dependency
  # The dynamic loader is named per architecture (ld-linux-aarch64.so.1, which an arm64 binary
  # built with -fstack-protector-strong needs for __stack_chk_guard), so the host has no copy of
  # the target's; on every architecture libc6 ships it beside libc.so.6.
  case $soname in
    ld-linux*.so.* | ld-*.so.*) soname=libc.so.6 ;;
  esac
  multiarch=$(gcc -print-multiarch 2>/dev/null || echo x86_64-linux-gnu)
  owner=$(dpkg -S "/lib/$multiarch/$soname" "/usr/lib/$multiarch/$soname" 2>/dev/null | head -1 | cut -d: -f1) || true
  if [ -z "$owner" ]; then
    echo "${0##*/}: no package on this machine provides $soname: install its $(dpkg --print-architecture) package" >&2
    exit 1
  fi
  name=${soname%%.so.*} soversion=${soname#*.so.}
  dependency=$(awk -v n="$name" -v v="$soversion" '$1 == n && $2 == v { $1 = ""; $2 = ""; sub(/^ +/, ""); print; exit }' \
    "$(dpkg-query --control-path "$owner" shlibs 2>/dev/null)" 2>/dev/null) || true
  echo "${dependency:-$owner (>= $(dpkg-query -W -f='${Version}' "$owner" | sed -E 's/^[0-9]+://; s/-[^-]*$//'))}"
}
