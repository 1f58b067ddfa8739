#!/usr/bin/env bash
# The table of docs/motion.md: raw, mean, kalman and rate side by side on simulated records
# from one seed, with the rate stream's model made by the calibration workflow itself
# (docs/calibration.md): a still record from a cold start → gyroctl analyze --write-model.
# About 10 s on a loaded 2-core machine (after the build).
#
#   scripts/motion-table.sh [SEED] [BUILD_DIR]      (defaults 1 and build)
set -euo pipefail
cd "$(dirname "$0")/.."
seed="${1:-1}"
build="${2:-build}"
cmake -S . -B "$build" -DGYROD_BUILD_BENCHMARKS=ON >/dev/null
cmake --build "$build" -j2 --target gyroctl compare_streams >/dev/null
bin="$build/bin"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# The simulated sensor (processing::comparisonSensor) as a model file, for gyroctl simulate.
"$bin/compare_streams" --write-sensor "$work/true.toml"
# The calibration record: 30 min still from a cold start, 25 → 40 °C (τ = 5 min).
"$bin/gyroctl" simulate --model "$work/true.toml" --warm-up 15,300 --duration 1800 --seed "$((seed + 1000))" \
  -o "$work/calibration.csv" 2>/dev/null
"$bin/gyroctl" analyze "$work/calibration.csv" --write-model "$work/sensor.toml" >/dev/null
"$bin/compare_streams" --model "$work/sensor.toml" --seed "$seed"
