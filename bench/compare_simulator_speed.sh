#!/bin/sh
# Old against new simulator speed in one run: builds bench/simulator_speed.cpp twice with
# the same compiler and flags, once against this tree's simulator sources and once against
# BASE's (git archive of processing/ at BASE, -DGYROD_BENCH_BASELINE), then runs the two
# binaries alternately and prints both tables. Not run by ctest.
#
#   bench/compare_simulator_speed.sh BASE [ROUNDS]
set -eu
if [ $# -lt 1 ]; then
  echo "usage: $0 BASE_COMMIT [ROUNDS]" >&2
  exit 2
fi
base=$1
rounds=${2:-3}
repo=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/base"
git -C "$repo" archive "$base" processing | tar -x -C "$tmp/base"
cp "$repo/bench/simulator_speed.cpp" "$tmp/base/simulator_speed.cpp"
# The simulator's sources as processing/CMakeLists.txt builds them (RelWithDebInfo's -O2,
# no FMA contraction for the four reproducible ones).
sources="processing/simulation/noise_simulator.cpp processing/simulation/sensor_model.cpp processing/base/portable_math.cpp processing/base/portable_random.cpp"
build() {  # root, output, extra flags
  ( cd "$1" && g++ -std=c++20 -O2 -DNDEBUG -ffp-contract=off $3 -I. $sources processing/base/noise_terms.cpp \
      "$2.cpp" -o "$2" )
}
build "$tmp/base" "$tmp/base/simulator_speed" -DGYROD_BENCH_BASELINE
cp "$repo/bench/simulator_speed.cpp" "$tmp/simulator_speed.cpp"
build "$repo" "$tmp/simulator_speed" ""
uptime
i=1
while [ "$i" -le "$rounds" ]; do
  echo "== round $i: base $base"
  "$tmp/base/simulator_speed" --repeats 3
  echo "== round $i: this tree"
  "$tmp/simulator_speed" --repeats 3
  i=$((i + 1))
done
uptime
