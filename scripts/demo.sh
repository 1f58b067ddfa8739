#!/usr/bin/env bash
# The main job: build, start gyrod on the mock MPU6050 (a simulated chip, in real time),
# show `gyroctl watch` streaming raw and filtered rates (the first 10 s are the still
# period in which gyrod estimates the bias and the filter), then the Allan table.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j"$(nproc)" --target gyrod gyroctl
sock=$PWD/build/demo-gyrod.sock
build/bin/gyrod --backend mock --socket "$sock" --log-level warn &
gyrod_pid=$!
trap 'kill -TERM $gyrod_pid 2>/dev/null; wait $gyrod_pid 2>/dev/null || true' EXIT
for _ in $(seq 100); do [ -S "$sock" ] && break; sleep 0.1; done
echo "== gyroctl watch (every 25th sample, 16 s) =="
build/bin/gyroctl watch --socket "$sock" --decimate 25 --count 32
echo
echo "== gyroctl allan =="
build/bin/gyroctl allan --socket "$sock"
echo
build/bin/gyroctl status --socket "$sock"
