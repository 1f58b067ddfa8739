#!/bin/sh
# False alarms of the live check through gyrod itself: N board-weeks of clean data, each a
# gyrod on the mock (50 Hz, the sensor model below: the paper's noise terms, a 0.5 deg/s bias)
# at `[mock] speed` (1000 by default: a week of data in about ten minutes), its check at the
# defaults (300 s intervals, 1800 s of baseline, 0.25 false alarms a week). Counts the effects
# named in gyrod's journal ("live check: new ...") and the data each run covered (STATUS's
# samples), and prints the rate per board-week with its 95 % upper bound (Poisson).
# docs/live-check.md, "False alarms".
#
#   bench/live_check_gyrod_weeks.sh [BUILD_DIR] [WEEKS] [PARALLEL] [SPEED]
set -eu
build=${1:-build}
weeks=${2:-4}
parallel=${3:-2}
speed=${4:-1000}
gyrod="$build/bin/gyrod"
gyroctl="$build/bin/gyroctl"
if [ ! -x "$gyrod" ] || [ ! -x "$gyroctl" ]; then
  echo "no $gyrod or $gyroctl: build first" >&2
  exit 66
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
week_s=604800
wall=$(awk -v w=$week_s -v s="$speed" 'BEGIN { printf "%d", w / s + 30 }')

cat > "$work/model.toml" <<'MODEL'
rate_hz = 50
[temperature]
start_c = 30
final_c = 30
time_constant_s = 900.0
noise_std_c = 0.02
MODEL
for axis in x y z; do
  cat >> "$work/model.toml" <<MODEL
[$axis]
quantization_urad = 0.1663
arw_deg_per_sqrt_h = 0.95164
bias_instability_deg_per_h = 0.60565
rrw_deg_per_h_sqrt_h = 0.07759
bias_dps = 0.5
[$axis.calibration]
bias_std_dps = 0.02
temperature_coefficient_dps_per_c = 0.0
temperature_coefficient_std_dps_per_c = 0.05
temperature_reference_c = 25.0
MODEL
done

# One board-week: gyrod with seed $1 in $work/$1; its data time and effects in $work/$1/result.
board_week() {
  dir="$work/$1"
  mkdir -p "$dir"
  cat > "$dir/gyrod.toml" <<CONFIG
[device]
backend = "mock"
rate_hz = 50
[filter]
model = "$work/model.toml"
[socket]
path = "$dir/gyrod.sock"
[mock]
speed = $speed
seed = $1
CONFIG
  "$gyrod" --config "$dir/gyrod.toml" > "$dir/log.txt" 2>&1 &
  pid=$!
  sleep "$wall"
  samples=$("$gyroctl" status --json --socket "$dir/gyrod.sock" 2>/dev/null |
    /usr/bin/python3 -c 'import json, sys; print(json.loads(sys.stdin.readline())["samples"])' || echo 0)
  kill -TERM "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
  named=$(grep -c "live check: new" "$dir/log.txt" || true)
  echo "$samples $named" > "$dir/result"
  grep "live check: new" "$dir/log.txt" | sed "s/^/board-week $1: /" || true
}

seed=1
while [ "$seed" -le "$weeks" ]; do
  batch=0
  while [ "$batch" -lt "$parallel" ] && [ "$seed" -le "$weeks" ]; do
    board_week "$seed" &
    seed=$((seed + 1))
    batch=$((batch + 1))
  done
  wait
done

# shellcheck disable=SC2016 # a Python program, not shell
cat "$work"/*/result | /usr/bin/python3 -c '
import math, sys
rows = [tuple(map(float, line.split())) for line in sys.stdin if line.strip()]
data_s = sum(r[0] for r in rows) / 50.0
named = int(sum(r[1] for r in rows))
weeks = data_s / 604800.0
# The 95 % upper bound of a Poisson mean for `named` events: P(N <= named; mu) = 0.05, by bisection.
def cdf(k, mu):
    term, total = math.exp(-mu), 0.0
    for i in range(k + 1):
        total += term
        term *= mu / (i + 1)
    return total
lo, hi = 0.0, 100.0 + 10.0 * named
for _ in range(200):
    mid = 0.5 * (lo + hi)
    lo, hi = (mid, hi) if cdf(named, mid) > 0.05 else (lo, mid)
print("%d runs, %.2f board-weeks of data through gyrod: %d effects named, %.3g per board-week "
      "(95 %% upper bound %.3g)" % (len(rows), weeks, named, named / weeks if weeks > 0 else float("nan"),
                                   hi / weeks if weeks > 0 else float("nan")))
'
