#!/usr/bin/env bash
# A cross-built .deb's Depends (scripts/deb-depends.sh, used by scripts/package.sh for arm64 and
# armhf): every library the binaries name maps to a package of this Debian release, the dynamic
# loader included (an arm64 gyrod built with -fstack-protector-strong names ld-linux-aarch64.so.1,
# and the ARM tier stopped at packaging on it); a library no package provides is an error that
# names it. Exits 77 (skipped) without dpkg.
#   tests/packaging/check-cross-depends.sh SOURCE_DIR
set -uo pipefail
source_dir=${1:?usage: check-cross-depends.sh SOURCE_DIR}
command -v dpkg-query >/dev/null 2>&1 || { echo "skipped: no dpkg on this machine"; exit 77; }
# shellcheck source=scripts/deb-depends.sh
. "$source_dir/scripts/deb-depends.sh"
failures=0
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}

libc=$(cross_depends libc.so.6) || fail "libc.so.6 has no Depends entry"
[[ $libc == libc6\ * || $libc == libc6 ]] || fail "libc.so.6 maps to '$libc', not libc6"
for loader in ld-linux-aarch64.so.1 ld-linux-armhf.so.3 ld-linux-x86-64.so.2; do
  got=$(cross_depends "$loader") || fail "$loader: no Depends entry"
  [ "$got" = "$libc" ] || fail "$loader maps to '$got', not to libc.so.6's '$libc'"
done
stdcxx=$(cross_depends libstdc++.so.6) || fail "libstdc++.so.6 has no Depends entry"
[[ $stdcxx == libstdc++6* ]] || fail "libstdc++.so.6 maps to '$stdcxx', not libstdc++6"

message=$( (cross_depends libgyrod-no-such-library.so.7) 2>&1 >/dev/null)
status=$?
[ "$status" -ne 0 ] || fail "a library no package provides was accepted"
[[ $message == *"libgyrod-no-such-library.so.7"* ]] || fail "the error does not name the library: '$message'"

if [ "$failures" -gt 0 ]; then
  echo "$failures check(s) failed" >&2
  exit 1
fi
echo "cross Depends: libc.so.6 and the loaders -> $libc; libstdc++.so.6 -> $stdcxx; a missing library named"
