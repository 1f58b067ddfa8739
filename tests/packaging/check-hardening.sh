#!/usr/bin/env bash
# Checks that binaries carry the hardening of cmake/Hardening.cmake, as lintian and
# hardening-check (devscripts) look for it in a Debian package:
#   bindnow    the dynamic section's FLAGS has BIND_NOW (or FLAGS_1 NOW)   -Wl,-z,now
#   relro      a GNU_RELRO segment                                         -Wl,-z,relro
#   stack      __stack_chk_fail imported                                   -fstack-protector-strong
#   fortify    at least one glibc __*_chk function imported                -D_FORTIFY_SOURCE=2
# readelf reads any architecture's ELF files, so a cross build's binaries are checked as they are.
# Usage: check-hardening.sh BINARY...
set -euo pipefail
[ $# -gt 0 ] || {
  echo "usage: check-hardening.sh BINARY..." >&2
  exit 2
}
failures=0
fail() {
  echo "check-hardening: $1: $2" >&2
  failures=$((failures + 1))
}
for binary in "$@"; do
  before=$failures
  dynamic=$(readelf -d -W "$binary")
  grep -qE '\(FLAGS\).*BIND_NOW|\(FLAGS_1\).*\bNOW\b' <<<"$dynamic" || fail "$binary" "not linked with -z now (no BIND_NOW)"
  readelf -l -W "$binary" | grep -q GNU_RELRO || fail "$binary" "not linked with -z relro (no GNU_RELRO segment)"
  imports=$(readelf --dyn-syms -W "$binary" | awk '$7 == "UND" { sub(/@.*/, "", $8); print $8 }')
  grep -qx '__stack_chk_fail' <<<"$imports" || fail "$binary" "no stack protector (__stack_chk_fail not imported)"
  fortified=$(grep -E '^__[a-z0-9_]+_chk$' <<<"$imports" | grep -cv '^__stack_chk_' || true)
  [ "$fortified" -gt 0 ] || fail "$binary" "no fortified glibc function imported (-D_FORTIFY_SOURCE)"
  [ "$failures" -ne "$before" ] ||
    echo "check-hardening: $binary: bindnow, relro, stack protector, $fortified fortified functions"
done
[ "$failures" -eq 0 ]
