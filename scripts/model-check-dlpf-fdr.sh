#!/usr/bin/env bash
# False-discovery rate per axis of `gyroctl model-check`'s core on clean gyrod-like data made
# through every DLPF setting and without one ("none": 50 Hz, FS_SEL 0, where the Gauss–Markov
# null is the joint fit's) (bench/model_check_dlpf_fdr.cpp), with the one-sided 95 %
# Clopper–Pearson upper bound per setting (0 of 300 axes: 1.0 %, the goal of issue 13). Not a
# unit test (about 0.5 s of CPU per axis at the defaults); the table it prints is in
# docs/model-check.md. Builds in build-bench/ so that the main build's options are left alone.
# The settings run as parallel jobs (JOBS, default nproc), one replica thread each.
#
#   scripts/model-check-dlpf-fdr.sh [SEEDS] [DURATION_S] [FIRST_SEED]   (defaults 100, 600, 1000)
# SETTINGS (default "none 6 5 4 0 3 1 2") picks the settings to run.
set -euo pipefail
cd "$(dirname "$0")/.."
seeds="${1:-100}"
duration="${2:-600}"
first="${3:-1000}"
settings="${SETTINGS:-none 6 5 4 0 3 1 2}"
jobs="${JOBS:-$(nproc)}"
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGYROD_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build-bench -j"$(nproc)" --target model_check_dlpf_fdr >/dev/null
bin=./build-bench/bin/model_check_dlpf_fdr
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
start=$(date +%s)
tr ' ' '\n' <<<"$settings" | xargs -P "$jobs" -I{} sh -c \
  "$bin --cfg {} --seeds $seeds --first $first --duration $duration --replicas 40 --threads 1 --rows-only 1 > $out/{}.txt" ||
  echo "model-check-dlpf-fdr: a setting's run failed or was stopped; its row is missing" >&2
echo "clean ${duration} s-at-50-Hz-length records (same sample count at every rate), $seeds seeds from $first x 3 axes per setting"
echo
echo "| DLPF_CFG | rate [Hz] | axes | false discoveries | per axis | 95 % upper bound | effects named |"
echo "|---|---|---|---|---|---|---|"
for cfg in none 0 1 2 3 4 5 6; do
  if [ -s "$out/$cfg.txt" ]; then cat "$out/$cfg.txt"; else echo "| $cfg | | | | | | not finished |"; fi
done
echo
echo "wall time $(( $(date +%s) - start )) s"
