#!/bin/sh
# The same command with several binaries, run in turn N times (interleaved, so that a slow
# phase of a shared machine falls on all of them alike), then each binary's minimum and mean
# wall and CPU (user + system) seconds from /usr/bin/time. A non-zero exit of the command is
# accepted (`analyze FILE --rate 1` stops after reading, which times the reading alone).
# Not run by ctest.
#
#   bench/interleaved_runs.sh N 'BIN analyze /tmp/a1e7.csv --axis gx' OLD_BINARY NEW_BINARY...
#     BIN in the command is replaced by each binary in turn.
set -eu
if [ $# -lt 3 ]; then
  echo "usage: $0 N 'COMMAND WITH BIN' BINARY..." >&2
  exit 2
fi
if [ ! -x /usr/bin/time ]; then echo "skipped: /usr/bin/time is missing (apt-get install time)"; exit 0; fi
runs=$1
command=$2
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
i=0
while [ "$i" -lt "$runs" ]; do
  k=0
  for binary in "$@"; do
    line=$(printf '%s\n' "$command" | sed "s|BIN|$binary|g")
    /usr/bin/time -f '%e %U %S' -o "$tmp/time" sh -c "$line" > /dev/null 2>&1 || true
    tail -n 1 "$tmp/time" >> "$tmp/$k"
    k=$((k + 1))
  done
  i=$((i + 1))
done
echo "load (1 min) at the end: $(cut -d' ' -f1 /proc/loadavg)"
k=0
for binary in "$@"; do
  awk -v name="$(basename "$binary")" '{ c = $2 + $3; if (NR == 1 || $1 < mw) mw = $1; if (NR == 1 || c < mc) mc = c; sw += $1; sc += c }
    END { printf "%-24s wall min %.2f s mean %.2f s   CPU min %.2f s mean %.2f s   (%d runs)\n", name, mw, sw / NR, mc, sc / NR, NR }' "$tmp/$k"
  k=$((k + 1))
done
