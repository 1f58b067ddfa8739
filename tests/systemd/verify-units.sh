#!/bin/sh
# Checks systemd/gyrod.service.in and systemd/gyrod.socket with `systemd-analyze verify`,
# and systemd/gyrod.sysusers with `systemd-sysusers --dry-run` (changes nothing).
# verify needs ExecStart's binary to exist, so the service is checked as a copy whose
# ExecStart is /bin/true. Exits 0 when clean, 1 on any complaint, 77 (ctest: skipped) when
# systemd-analyze is not installed (Debian package: systemd).
# Usage: verify-units.sh [SOURCE_DIR]   (default: the repository containing this script)
set -eu
src=${1:-$(cd "$(dirname "$0")/../.." && pwd)}
if ! command -v systemd-analyze >/dev/null 2>&1; then
  echo "SKIP: systemd-analyze not found (apt-get install systemd)"
  exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed 's|@GYROD_BINDIR@/gyrod|/bin/true|' "$src/systemd/gyrod.service.in" >"$work/gyrod.service"
cp "$src/systemd/gyrod.socket" "$work/gyrod.socket"
if grep -n '@[A-Z_]*@' "$work/gyrod.service"; then
  echo "FAIL: unsubstituted @VARIABLE@ left in gyrod.service"
  exit 1
fi
# Units of the same directory find each other (Also=, the socket's service).
out=$(cd "$work" && SYSTEMD_LOG_LEVEL=notice systemd-analyze verify --man=no ./gyrod.service ./gyrod.socket 2>&1) || {
  echo "$out"
  echo "FAIL: systemd-analyze verify exited non-zero"
  exit 1
}
# verify reports most problems as log lines while still exiting 0: any line about our
# units counts as a failure.
problems=$(printf '%s\n' "$out" | grep -E 'gyrod\.(service|socket)' || true)
if [ -n "$problems" ]; then
  printf '%s\n' "$problems"
  echo "FAIL: systemd-analyze verify complained"
  exit 1
fi
# The event loop must run SCHED_FIFO: under SCHED_OTHER a busy CPU delays data-ready
# wake-ups by a scheduler tick (docs/driver.md "Latency").
if ! grep -qx 'CPUSchedulingPolicy=fifo' "$work/gyrod.service" ||
  ! grep -qxE 'CPUSchedulingPriority=[1-9][0-9]?' "$work/gyrod.service"; then
  echo "FAIL: gyrod.service must set CPUSchedulingPolicy=fifo and CPUSchedulingPriority=1..99"
  exit 1
fi
# The sysusers.d entry: a dry run parses it and prints what it would create.
if command -v systemd-sysusers >/dev/null 2>&1; then
  if ! systemd-sysusers --dry-run "$src/systemd/gyrod.sysusers" >"$work/sysusers.log" 2>&1 ||
    grep -E 'gyrod\.sysusers:[0-9]+' "$work/sysusers.log"; then
    cat "$work/sysusers.log"
    echo "FAIL: systemd-sysusers rejects gyrod.sysusers"
    exit 1
  fi
fi
echo "ok: gyrod.service, gyrod.socket and gyrod.sysusers check cleanly ($(systemd-analyze --version | head -1))"
