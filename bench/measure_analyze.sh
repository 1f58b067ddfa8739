#!/bin/sh
# gyroctl analyze on recordings of growing length, side by side in one run (issue 15): wall,
# CPU (user + system), CPU/wall, peak RSS and bytes a sample per axis from /usr/bin/time, for
# this build and optionally a baseline binary, then bench_allan's ratio. The load average is
# printed before every row: on a shared machine compare CPU seconds and memory, not wall.
# Not run by ctest.
#
#   bench/measure_analyze.sh [--gyroctl BIN] [--baseline BIN] [--steps] FILE[:AXES]...
#     FILE:1 analyses --axis gx (the default), FILE:3 every axis.
#     --steps: then each file once more with GYROD_ANALYZE_TIMING=1, the wall and CPU seconds
#     of every step of this build (reading, checks, each axis's tests, Allan, mean filter, ...).
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
gyroctl="$repo/build/bin/gyroctl"
baseline=""
steps=""
while [ $# -gt 0 ]; do
  case "$1" in
    --gyroctl) gyroctl=$2; shift 2 ;;
    --baseline) baseline=$2; shift 2 ;;
    --steps) steps=1; shift ;;
    --) shift; break ;;
    -*) echo "usage: $0 [--gyroctl BIN] [--baseline BIN] [--steps] FILE[:AXES]..." >&2; exit 2 ;;
    *) break ;;
  esac
done
specs="$*"  # file names without spaces (the loop below reuses "$@")
if [ ! -x /usr/bin/time ]; then echo "skipped: /usr/bin/time is missing (apt-get install time)"; exit 0; fi
timing=$(mktemp)
trap 'rm -f "$timing"' EXIT

# row LABEL SAMPLES AXES COMMAND...
row() {
  label=$1 samples=$2 axes=$3
  shift 3
  load=$(cut -d' ' -f1 /proc/loadavg)
  /usr/bin/time -f '%e %U %S %M' -o "$timing" "$@" > /dev/null
  read -r wall user sys kb < "$timing"
  awk -v l="$label" -v w="$wall" -v u="$user" -v s="$sys" -v kb="$kb" -v n="$samples" -v a="$axes" -v load="$load" \
    'BEGIN { cpu = u + s; printf "| %s | %.2f s | %.2f s | %.2f | %d MB | %.1f | %s |\n", l, w, cpu, cpu / w, kb / 1024, kb * 1024 / n / a, load }'
}

echo "| command | wall | CPU | CPU/wall | peak RSS | B/sample/axis | load (1 min) |"
echo "|---|---|---|---|---|---|---|"
for spec in "$@"; do
  file=${spec%:*}
  axes=1
  case "$spec" in *:3) axes=3 ;; esac
  samples=$(($(grep -c '^[0-9-]' "$file")))
  if [ "$axes" = 3 ]; then set -- ; else set -- --axis gx; fi
  for bin in $baseline "$gyroctl"; do
    name=$(basename "$bin")
    row "$name analyze $(basename "$file") $* ($samples samples)" "$samples" "$axes" "$bin" analyze "$file" "$@"
  done
done
if [ -n "$steps" ]; then
  for spec in $specs; do
    file=${spec%:*}
    echo
    case "$spec" in
      *:3) echo "steps of $(basename "$gyroctl") analyze $(basename "$file") (load $(cut -d' ' -f1 /proc/loadavg)):"
           GYROD_ANALYZE_TIMING=1 "$gyroctl" analyze "$file" 2>&1 > /dev/null ;;
      *) echo "steps of $(basename "$gyroctl") analyze $(basename "$file") --axis gx (load $(cut -d' ' -f1 /proc/loadavg)):"
         GYROD_ANALYZE_TIMING=1 "$gyroctl" analyze "$file" --axis gx 2>&1 > /dev/null ;;
    esac
  done
fi
bench="$(dirname "$gyroctl")/bench_allan"
if [ -x "$bench" ]; then
  echo
  "$bench" --benchmark_filter=NONE 2> /dev/null | tail -n 1
fi
