#!/usr/bin/env bash
# Detection curves of the model check against the detectors that know each effect's form and,
# where it is measured, the blind bound (bench/model_check_curves.cpp): prints the tables and
# draws docs/img/model-check-*.png with
# gnuplot. Not a unit test (tens of minutes on a loaded 2-core machine; ctest runs the
# program's --quick mode instead, scripts/check-model-check-curves.sh).
#
#   scripts/model-check-curves.sh [TRIALS_10MIN] [TRIALS_1H] [EFFECTS_1H] [CLEAN_10MIN]
#     defaults 10, 5, "bias_steps,gauss_markov_long" and 30; the curves run as parallel jobs
#     (nice -n 10); their tables go to build/model-check-curves/*.txt and to stdout.
#   PLOT_ONLY=1 scripts/model-check-curves.sh   redraws the PNGs from the last run's tables
set -euo pipefail
cd "$(dirname "$0")/.."
trials_short="${1:-10}"
trials_long="${2:-5}"
effects_long="${3:-bias_steps,gauss_markov_long}"
clean_short="${4:-30}"
data=build/model-check-curves
mkdir -p "$data" docs/img
if [ -z "${PLOT_ONLY:-}" ]; then
rm -f "$data"/*.dat "$data"/*.txt
cmake -S . -B build -DGYROD_BUILD_BENCHMARKS=ON >/dev/null
cmake --build build -j2 --target model_check_curves >/dev/null
start=$(date +%s)
run() {  # NAME DURATION EFFECTS TRIALS CLEAN
  nice -n 10 ./build/bin/model_check_curves --durations "$2" --effects "$3" --trials "$4" --clean "$5" \
    --data "$data" >"$data/$1.txt"
}
run short-a 600 bias_steps,sinusoid "$trials_short" 0 &
run short-b 600 temperature_bias,gauss_markov_short "$trials_short" 0 &
run short-c 600 gauss_markov_long "$trials_short" "$clean_short" &
if [ "$trials_long" -gt 0 ]; then
  IFS=, read -ra long_effects <<<"$effects_long"
  for e in "${long_effects[@]}"; do run "long-$e" 3600 "$e" "$trials_long" 0 & done
fi
wait
cat "$data"/*.txt
echo "wall time $(( $(date +%s) - start )) s"
fi
command -v gnuplot >/dev/null || { echo "gnuplot not installed: tables only" >&2; exit 0; }
for dat in "$data"/*-600.dat; do
  name=$(basename "$dat" -600.dat)
  long="$data/$name-3600.dat"
  what=$(head -1 "$dat" | sed -e 's/^# //' -e 's/, 600 s:.*//')
  plot="'$dat' u 1:2:3:4 w yerrorlines lw 2 lc rgb '#d62728' t 'model check, 10 min', \
        '$dat' u 1:5:6:7 w yerrorlines lw 2 dt 2 lc rgb '#1f77b4' t 'known form, 10 min'"
  # The blind bound, where the table measures it (columns 8-10).
  bound() { awk '!/^#/ { exit !(NF >= 10) }' "$1"; }
  if bound "$dat"; then
    plot="$plot, '$dat' u 1:8:9:10 w yerrorlines lw 2 dt 4 lc rgb '#2ca02c' t 'blind bound, 10 min'"
  fi
  if [ -f "$long" ]; then
    plot="$plot, '$long' u 1:2:3:4 w yerrorlines lw 2 lc rgb '#ff7f0e' t 'model check, 1 h', \
          '$long' u 1:5:6:7 w yerrorlines lw 2 dt 2 lc rgb '#17becf' t 'known form, 1 h'"
    if bound "$long"; then
      plot="$plot, '$long' u 1:8:9:10 w yerrorlines lw 2 dt 4 lc rgb '#9467bd' t 'blind bound, 1 h'"
    fi
  fi
  gnuplot <<GP
set terminal pngcairo size 720,440 font ",10" noenhanced
set output "docs/img/model-check-$name.png"
set title "$name: detection probability (Wilson 95 % intervals)"
set xlabel "$what"
set ylabel "P(detect)"
set logscale x
set autoscale xfix
set offsets graph 0.03, graph 0.03, 0, 0
set yrange [-0.02:1.02]
set grid
set key bottom right
set arrow from graph 0, first 0.5 to graph 1, first 0.5 nohead dt 3 lc rgb "gray"
plot $plot
GP
done
ls -1 docs/img/model-check-*.png
