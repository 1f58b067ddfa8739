#!/bin/sh
# gyroctl analyze against allantools on the same single-axis CSV, side by side in one run
# (issue 15's table): wall time and peak memory from /usr/bin/time, for
#   allantools: np.loadtxt + oadev(taus='octave')   (load and oadev also timed apart)
#   gyroctl analyze FILE --axis gx                   (everything it prints)
#   gyroctl analyze FILE --axis gx --taus octave --no-detrend --json
#   gyroctl analyze FILE --axis gx --taus 0.02       (a single tau)
#   gyroctl analyze FILE3 (three axes)
# Skips cleanly (exit 0, saying why) without Debian's python3-numpy and python3-scipy for
# /usr/bin/python3, or without an allantools checkout (the gyroctl rows are still printed
# unless --require-allantools). Not run by ctest; the benchmark numbers do not depend on it.
#
#   bench/compare_allantools.sh [--samples N] [--allantools DIR] [--gyroctl BIN] [--workdir DIR]
set -eu
samples=10000000
allantools=""
repo=$(cd "$(dirname "$0")/.." && pwd)
gyroctl="$repo/build/bin/gyroctl"
workdir=${TMPDIR:-/tmp}/gyrod-compare-allantools
while [ $# -gt 0 ]; do
  case "$1" in
    --samples) samples=$2; shift 2 ;;
    --allantools) allantools=$2; shift 2 ;;
    --gyroctl) gyroctl=$2; shift 2 ;;
    --workdir) workdir=$2; shift 2 ;;
    *) echo "usage: $0 [--samples N] [--allantools DIR] [--gyroctl BIN] [--workdir DIR]" >&2; exit 2 ;;
  esac
done
if [ ! -x /usr/bin/time ]; then echo "skipped: /usr/bin/time is missing (apt-get install time)"; exit 0; fi
if [ ! -x "$gyroctl" ]; then echo "skipped: no gyroctl at $gyroctl (build it, or pass --gyroctl)"; exit 0; fi
have_allantools=yes
if ! /usr/bin/python3 -c 'import numpy, scipy' 2>/dev/null; then
  echo "note: no python3-numpy/python3-scipy for /usr/bin/python3: the allantools row is skipped"
  have_allantools=no
elif [ -z "$allantools" ] || [ ! -f "$allantools/allantools/allantools.py" ]; then
  echo "note: no allantools checkout given (--allantools DIR): the allantools row is skipped"
  have_allantools=no
fi

mkdir -p "$workdir"
rate=50
duration=$(awk -v n="$samples" -v r="$rate" 'BEGIN { printf "%.10g", n / r }')
three="$workdir/three-$samples.csv"
one="$workdir/one-$samples.csv"
if [ ! -s "$one" ]; then
  "$gyroctl" simulate --duration "$duration" --rate "$rate" --arw 0.5 --bias-instability 5 --rrw 2 --seed 3 \
    -o "$three" > /dev/null
  cut -d, -f1,2 "$three" > "$one"
fi

# run LABEL COMMAND...: wall seconds and peak RSS in MB of one command, as a table row.
run() {
  label=$1
  shift
  /usr/bin/time -f '%e %M' -o "$workdir/time.txt" "$@" > "$workdir/out.txt" 2> "$workdir/err.txt" || {
    echo "failed: $label" >&2
    cat "$workdir/err.txt" >&2
    exit 1
  }
  read -r wall kb < "$workdir/time.txt"
  printf '| %s | %s s | %d MB |\n' "$label" "$wall" $((kb / 1024))
}

echo "$samples samples, one axis: $(du -mL "$one" | cut -f1) MB of CSV; load: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| | wall | peak memory |"
echo "|---|---|---|"
if [ "$have_allantools" = yes ]; then
  cat > "$workdir/allantools_oadev.py" << 'EOF'
import sys, time
sys.path.insert(0, sys.argv[1])
import numpy as np
import allantools
t0 = time.perf_counter()
y = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1, usecols=1)
t1 = time.perf_counter()
taus, adev, err, n = allantools.oadev(y, rate=float(sys.argv[3]), data_type="freq", taus="octave")
t2 = time.perf_counter()
print(f"load {t1 - t0:.2f} s, oadev {t2 - t1:.2f} s, {len(taus)} taus", file=sys.stderr)
EOF
  run "allantools: np.loadtxt + oadev(taus='octave')" /usr/bin/python3 "$workdir/allantools_oadev.py" \
    "$allantools" "$one" "$rate"
  echo "|   (of which) | $(cat "$workdir/err.txt") | |"
fi
run "gyroctl analyze FILE --axis gx (everything)" "$gyroctl" analyze "$one" --axis gx
run "gyroctl analyze FILE --axis gx --taus octave --no-detrend --json" "$gyroctl" analyze "$one" --axis gx \
  --taus octave --no-detrend --json
run "the same with --taus 0.02 (a single tau)" "$gyroctl" analyze "$one" --axis gx --taus 0.02 --no-detrend --json
if [ -s "$three" ]; then
  run "gyroctl analyze FILE3 (three axes and temp, everything)" "$gyroctl" analyze "$three"
fi
bench="$(dirname "$gyroctl")/bench_allan"
if [ -x "$bench" ]; then
  echo
  "$bench" --benchmark_filter=NONE 2> /dev/null | tail -n 1
fi
