#!/usr/bin/env bash
# Detection rate, false-discovery rate and parameter errors of `gyroctl model-check`'s core
# over many seeds of the hidden-effect generator (bench/model_check_rates.cpp). Not a unit
# test (minutes, not seconds); the table it prints is in docs/model-check.md.
#
#   scripts/model-check-rates.sh [SEEDS] [DURATION_S]     (defaults 200 and 600)
set -euo pipefail
cd "$(dirname "$0")/.."
seeds="${1:-200}"
duration="${2:-600}"
cmake -S . -B build -DGYROD_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build -j"$(nproc)" --target model_check_rates >/dev/null
for mode in single clean two; do
  n="$seeds"
  [ "$mode" != single ] && n=$(( (seeds + 1) / 2 ))
  ./build/bin/model_check_rates --mode "$mode" --seeds "$n" --duration "$duration" --replicas 40
  echo
done
