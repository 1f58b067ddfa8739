#!/usr/bin/env bash
# The main job: build, start gyrod on the mock MPU6050 (a simulated chip, in real time) that
# is turned twice about z (360 deg at 90 deg/s, from t = 5 s, 2 s still after each turn),
# show `gyroctl watch` streaming rate, raw and the paper's kalman side by side (the first 4 s
# are the still period in which gyrod estimates the bias and the paper's filter: rate and
# kalman show "-" there), then the Allan table and the status.
# rate follows the turns (about 90 on z); kalman, the paper's filter for a gyro at rest,
# shrinks them to less than half (docs/motion.md).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j"$(nproc)" --target gyrod gyroctl
sock=$PWD/build/demo-gyrod.sock
config=$PWD/build/demo-gyrod.toml
cat >"$config" <<'TOML'
[device]
backend = "mock"
[bias]
still_seconds = 4
[mock]
motion = "turns:axis=z,count=2,rate=90,still=2,start=5"
TOML
build/bin/gyrod --config "$config" --socket "$sock" --log-level warn &
gyrod_pid=$!
trap 'kill -TERM $gyrod_pid 2>/dev/null; wait $gyrod_pid 2>/dev/null || true' EXIT
for _ in $(seq 100); do [ -S "$sock" ] && break; sleep 0.1; done
echo "== gyroctl watch (every 25th sample, 16 s; two turns about z at 90 deg/s from t = 5 s) =="
echo "   rate: the stream to read while the board moves (here raw - the start-up bias: no model file,"
echo "   docs/calibration.md); kalman: the paper's filter, which characterises the gyro at rest"
build/bin/gyroctl watch --socket "$sock" --decimate 25 --count 32
echo
echo "== gyroctl allan =="
build/bin/gyroctl allan --socket "$sock"
echo
build/bin/gyroctl status --socket "$sock"
