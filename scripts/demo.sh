#!/usr/bin/env bash
# The main job, for now: build, import a real MPU6050 recording shipped with the project
# (third-party, MIT, see tests/data/mpu6050-arduino-100hz/) and print the paper's tables.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j"$(nproc)" --target gyroctl
build/bin/gyroctl import tests/data/mpu6050-arduino-100hz/example_data_tinit_calc.csv -o build/real-mpu6050.csv
build/bin/gyroctl analyze build/real-mpu6050.csv
