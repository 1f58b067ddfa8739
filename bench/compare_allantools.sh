#!/bin/sh
# gyroctl analyze against allantools on the same single-axis CSV, side by side (issue 15's
# table), in R interleaved rounds so that a slow phase of a shared machine falls on both alike.
# Each round runs, one after the other:
#   allantools: np.loadtxt + oadev(taus='octave')   (load and oadev also timed apart, in Python)
#   gyroctl analyze FILE --axis gx                   (everything it prints)
#   gyroctl analyze FILE --axis gx --taus octave --no-detrend --json
#   gyroctl analyze FILE --axis gx --taus 0.02       (a single tau)
#   gyroctl analyze FILE3                            (three axes and temperature)
#   bench_allan's OADEV at every octave tau in memory (kept workspace), when it is built
# and prints per row the median wall time, peak memory, and the median over rounds of
# allantools' wall / the row's wall (each ratio from one round; none for the three axes, as
# allantools reads one). The last table sets the
# OADEV core beside allantools' oadev alone and one streaming sum. allantools' OADEV values are
# checked against gyroctl's (`--json`, the same m): the largest relative difference is printed.
# Skips the allantools rows (exit 0, saying why) without Debian's python3-numpy and
# python3-scipy for /usr/bin/python3, or without an allantools checkout
# (https://github.com/aewallin/allantools); --require-allantools makes that an error.
# Not run by ctest; the benchmark numbers do not depend on it.
#
#   bench/compare_allantools.sh [--samples N] [--rounds R] [--allantools DIR] [--gyroctl BIN]
#                               [--workdir DIR] [--require-allantools]
set -eu
samples=10000000
rounds=3
allantools=""
require=no
repo=$(cd "$(dirname "$0")/.." && pwd)
gyroctl="$repo/build/bin/gyroctl"
workdir=${TMPDIR:-/tmp}/gyrod-compare-allantools
usage="usage: $0 [--samples N] [--rounds R] [--allantools DIR] [--gyroctl BIN] [--workdir DIR] [--require-allantools]"
while [ $# -gt 0 ]; do
  case "$1" in
    --samples) samples=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --allantools) allantools=$2; shift 2 ;;
    --gyroctl) gyroctl=$2; shift 2 ;;
    --workdir) workdir=$2; shift 2 ;;
    --require-allantools) require=yes; shift ;;
    *) echo "$usage" >&2; exit 2 ;;
  esac
done
case "$rounds" in '' | *[!0-9]* | 0) echo "--rounds wants a positive integer, not '$rounds'" >&2; exit 2 ;; esac
if [ ! -x /usr/bin/time ]; then echo "skipped: /usr/bin/time is missing (apt-get install time)"; exit 0; fi
if [ ! -x "$gyroctl" ]; then echo "skipped: no gyroctl at $gyroctl (build it, or pass --gyroctl)"; exit 0; fi
have_allantools=yes
why=""
if ! /usr/bin/python3 -c 'import numpy, scipy' 2> /dev/null; then
  why="no python3-numpy/python3-scipy for /usr/bin/python3 (apt-get install python3-numpy python3-scipy)"
elif [ -z "$allantools" ] || [ ! -f "$allantools/allantools/allantools.py" ]; then
  why="no allantools checkout given (--allantools DIR, a clone of github.com/aewallin/allantools)"
fi
if [ -n "$why" ]; then
  if [ "$require" = yes ]; then echo "error: $why" >&2; exit 1; fi
  echo "note: $why: the allantools rows are skipped"
  have_allantools=no
fi

mkdir -p "$workdir"
rate=50
duration=$(awk -v n="$samples" -v r="$rate" 'BEGIN { printf "%.10g", n / r }')
three="$workdir/three-$samples.csv"
one="$workdir/one-$samples.csv"
if [ ! -s "$one" ]; then
  "$gyroctl" simulate --duration "$duration" --rate "$rate" --arw 0.5 --bias-instability 5 --rrw 2 --seed 3 \
    -o "$three" > "$workdir/simulate.log" 2>&1 || { cat "$workdir/simulate.log" >&2; exit 1; }
  cut -d, -f1,2 "$three" > "$one"
fi
times="$workdir/times"
rm -rf "$times" "$workdir/agreement"
mkdir -p "$times"

# run KEY COMMAND...: appends "wall_s peak_kB" of one run of COMMAND to $times/KEY; its
# standard output is kept in $workdir/KEY.out, its standard error in $workdir/KEY.err.
run() {
  key=$1
  shift
  /usr/bin/time -f '%e %M' -o "$workdir/time.txt" "$@" > "$workdir/$key.out" 2> "$workdir/$key.err" || {
    echo "failed: $*" >&2
    cat "$workdir/$key.err" >&2
    exit 1
  }
  tail -n 1 "$workdir/time.txt" >> "$times/$key"
}

if [ "$have_allantools" = yes ]; then
  # Times np.loadtxt and oadev apart; with a gyroctl JSON document given, the largest relative
  # difference between the two OADEV tables at the m both have (allantools' m = tau·rate).
  cat > "$workdir/allantools_oadev.py" << 'PY'
import json, sys, time
sys.path.insert(0, sys.argv[1])
import numpy as np
import allantools
rate = float(sys.argv[3])
t0 = time.perf_counter()
y = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1, usecols=1)
t1 = time.perf_counter()
taus, adev, err, n = allantools.oadev(y, rate=rate, data_type="freq", taus="octave")
t2 = time.perf_counter()
print(f"{t1 - t0:.3f} {t2 - t1:.3f} {len(taus)}")
if len(sys.argv) > 4:
    with open(sys.argv[4]) as f:
        ours = {row["m"]: row["oadev"] for row in json.load(f)["axes"]["gx"]["allan"]}
    worst, compared = 0.0, 0
    for tau, dev in zip(taus, adev):
        m = int(round(tau * rate))
        if m in ours:
            worst = max(worst, abs(ours[m] - dev) / dev)
            compared += 1
    print(f"{compared} {worst:.3g}")
PY
fi

bench="$(dirname "$gyroctl")/bench_allan"
echo "$samples samples at $rate Hz, one axis: $(du -mL "$one" | cut -f1) MB of CSV; three axes: $(du -mL "$three" | cut -f1) MB;" \
  "$rounds interleaved rounds; load at the start: $(cut -d' ' -f1-3 /proc/loadavg)"
json="$workdir/gyroctl-octave.json"
rm -f "$json"
r=0
while [ "$r" -lt "$rounds" ]; do
  if [ "$have_allantools" = yes ]; then
    # From the second round on, the values are compared with the JSON of the round before.
    if [ -s "$json" ]; then
      run allantools /usr/bin/python3 "$workdir/allantools_oadev.py" "$allantools" "$one" "$rate" "$json"
      sed -n 2p "$workdir/allantools.out" > "$workdir/agreement"
    else
      run allantools /usr/bin/python3 "$workdir/allantools_oadev.py" "$allantools" "$one" "$rate"
    fi
    head -n 1 "$workdir/allantools.out" >> "$times/allantools-parts"
  fi
  run everything "$gyroctl" analyze "$one" --axis gx
  run octave "$gyroctl" analyze "$one" --axis gx --taus octave --no-detrend --json
  cp "$workdir/octave.out" "$json"
  run single "$gyroctl" analyze "$one" --axis gx --taus 0.02 --no-detrend --json
  run three "$gyroctl" analyze "$three"
  if [ -x "$bench" ]; then
    # "the same in a workspace kept between calls (...): W ms wall, C ms CPU; ..." and the
    # streaming sum's wall from the line before.
    "$bench" --benchmark_filter=NONE 2> /dev/null | awk '
      /^overlapping ADEV/ { for (i = 1; i <= NF; ++i) if ($i == "sum:") sum = $(i + 1) }
      /^the same in a workspace/ { for (i = 1; i <= NF; ++i) if ($i == "ms" && $(i + 1) == "wall,") { print $(i - 1) / 1000, sum / 1000; exit } }' \
      >> "$times/oadev-core"
  fi
  r=$((r + 1))
done
echo "load at the end: $(cut -d' ' -f1-3 /proc/loadavg)"

# middle FORMAT: the median of the numbers on standard input, one a line, printed with FORMAT.
middle() {
  sort -g | awk -v f="$1" '{ v[NR] = $1 } END { printf f, NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}
# median FILE COLUMN: the median of one column.
median() {
  awk -v c="$2" '{ print $c }' "$1" | middle '%.10g\n'
}
# ratio_median A B: the median over rounds of A's wall / B's wall (line i of each file).
ratio_median() {
  paste -d' ' "$times/$1" "$times/$2" | awk '{ print $1 / $3 }' | middle '%.2f'
}
row() {
  key=$1
  label=$2
  wall=$(median "$times/$key" 1)
  mb=$(($(median "$times/$key" 2) / 1024))
  ratio=""
  if [ "$have_allantools" = yes ] && [ "$key" != allantools ] && [ "$key" != three ]; then
    ratio="$(ratio_median allantools "$key")×"
  fi
  printf '| %s | %.2f s | %d MB | %s |\n' "$label" "$wall" "$mb" "$ratio"
}

echo
echo "| | wall (median) | peak memory | allantools' wall / this (median of rounds) |"
echo "|---|---|---|---|"
if [ "$have_allantools" = yes ]; then
  row allantools "allantools: np.loadtxt + oadev(taus='octave')"
  printf '|   of which load, oadev (median) | %.2f s, %.2f s (%s τ) | | |\n' "$(median "$times/allantools-parts" 1)" \
    "$(median "$times/allantools-parts" 2)" "$(head -n 1 "$times/allantools-parts" | cut -d' ' -f3)"
fi
row everything "gyroctl analyze FILE --axis gx (everything it prints)"
row octave "gyroctl analyze FILE --axis gx --taus octave --no-detrend --json"
row single "the same with --taus 0.02 (a single τ)"
row three "gyroctl analyze FILE3 (three axes and temperature, everything)"
if [ "$have_allantools" = yes ]; then
  echo
  echo "peak memory, gyroctl (everything) / allantools: $(paste -d' ' "$times/everything" "$times/allantools" |
    awk '{ print $2 / $4 }' | middle '%.2f')"
  if [ ! -s "$workdir/agreement" ]; then  # one round: compare once more, untimed
    /usr/bin/python3 "$workdir/allantools_oadev.py" "$allantools" "$one" "$rate" "$json" | sed -n 2p > "$workdir/agreement"
  fi
  read -r compared worst < "$workdir/agreement" || true
  if [ "${compared:-0}" -gt 0 ]; then
    echo "OADEV, gyroctl against allantools at the $compared octave m both print: largest relative difference $worst"
  else
    echo "OADEV: allantools and gyroctl printed no m in common; nothing compared"
  fi
fi
if [ -s "$times/oadev-core" ]; then
  echo
  echo "| OADEV at every octave τ on 10⁷ samples, in memory | wall (median) | this / one streaming sum | allantools' oadev / this |"
  echo "|---|---|---|---|"
  core=$(median "$times/oadev-core" 1)
  sum_ratio=$(awk '{ print $1 / $2 }' "$times/oadev-core" | middle '%.1f')
  if [ "$have_allantools" = yes ] && [ "$samples" -eq 10000000 ]; then  # bench_allan's size
    oadev_ratio="$(paste -d' ' "$times/allantools-parts" "$times/oadev-core" | awk '{ print $2 / $4 }' | middle '%.1f')×"
  else
    oadev_ratio="(only with --samples 10000000, bench_allan's size)"
  fi
  printf '| bench_allan (workspace kept, as analyze) | %.3f s | %s× | %s |\n' "$core" "$sum_ratio" "$oadev_ratio"
fi
