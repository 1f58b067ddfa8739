#!/usr/bin/env bash
# False-discovery rate per axis of `gyroctl model-check`'s core on clean gyrod-like data made
# through every DLPF setting (bench/model_check_dlpf_fdr.cpp). Not a unit test (minutes); the
# table it prints is in docs/model-check.md. Builds in build-bench/ so that the main build's
# options are left alone.
#
#   scripts/model-check-dlpf-fdr.sh [SEEDS] [DURATION_S]     (defaults 20 and 600)
set -euo pipefail
cd "$(dirname "$0")/.."
seeds="${1:-20}"
duration="${2:-600}"
cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGYROD_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build-bench -j"$(nproc)" --target model_check_dlpf_fdr >/dev/null
./build-bench/bin/model_check_dlpf_fdr --seeds "$seeds" --duration "$duration" --replicas 40
