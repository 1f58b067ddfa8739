#!/usr/bin/env bash
# The main job, as a user with a new board goes through it:
#  1. calibrate: gyrod records the mock MPU6050 (a simulated chip) at rest through its
#     warm-up, 20 minutes of it at 100x real time (about 13 s), and `gyroctl analyze
#     --write-model` turns the recording into a sensor model (docs/calibration.md);
#  2. run: gyrod on the same mock in real time with that model, the board turned twice about
#     z (360 deg at 90 deg/s from t = 6 s, 1 s still between) and then tilted 30 deg about x
#     and back (t = 16-22 s); `gyroctl watch` streams rate, raw and the paper's kalman side by
#     side, and the orientation: roll, pitch and heading. The first 4 s are the still period in
#     which gyrod checks the bias and starts the paper's filter (kalman shows "-" there).
#     rate follows the motion (about 90 on z); kalman, the paper's filter for a gyro at rest,
#     shrinks it to less than half (docs/motion.md); heading runs through each turn and back
#     to 0, roll goes to 30 and back (docs/attitude.md);
#  3. the Allan table and the status.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j"$(nproc)" --target gyrod gyroctl
work=$PWD/build/demo
rm -rf "$work"
mkdir -p "$work/still"
sock=$work/gyrod.sock

echo "== 1. calibration: 20 min of the mock at rest, recorded at 100x real time =="
cat >"$work/calibrate.toml" <<'TOML'
[device]
backend = "mock"
[mock]
speed = 100
[record]
rotate_mb = 0
TOML
build/bin/gyrod --config "$work/calibrate.toml" --socket "$sock" --record "$work/still/" --log-level warn &
gyrod_pid=$!
trap 'kill -TERM $gyrod_pid 2>/dev/null; wait $gyrod_pid 2>/dev/null || true' EXIT
sleep 12.5
kill -TERM "$gyrod_pid"
wait "$gyrod_pid"
still=$(ls "$work"/still/*.csv)
build/bin/gyroctl analyze "$still" --write-model "$work/sensor.toml" >"$work/analyze.txt"
echo "gyroctl analyze $(basename "$still") --write-model sensor.toml:"
sed -n 's/^# \(g[xyz]: bias\)/   \1/p' "$work/sensor.toml"
echo

cat >"$work/gyrod.toml" <<TOML
[device]
backend = "mock"
[bias]
still_seconds = 4
[filter]
model = "$work/sensor.toml"
[mock]
motion = "turns:axis=z,count=2,rate=90,still=1,start=5 + constant:axis=x,rate=15,start=16,duration=2 + constant:axis=x,rate=-15,start=20,duration=2"
TOML
build/bin/gyrod --config "$work/gyrod.toml" --socket "$sock" --log-level warn &
gyrod_pid=$!
for _ in $(seq 100); do [ -S "$sock" ] && break; sleep 0.1; done
echo "== 2. gyroctl watch (every 25th sample, 24 s; two turns about z at 90 deg/s from t = 6 s,"
echo "   a 30 deg tilt about x from t = 16 s and back) =="
echo "   rate: the stream to read while the board moves (raw - the model's bias at the die's"
echo "   temperature); kalman: the paper's filter, which characterises the gyro at rest;"
echo "   roll, pitch, heading: the orientation from rate and the accelerometer"
build/bin/gyroctl watch --socket "$sock" --decimate 25 --count 48
echo
echo "== 3. gyroctl allan =="
build/bin/gyroctl allan --socket "$sock"
echo
build/bin/gyroctl status --socket "$sock"
