#!/usr/bin/env bash
# analyse → model → simulate → analyse round trip: simulate a recording from known noise
# terms, fit the model back with `gyroctl analyze --write-model`, and print term in, term
# out and the fit's 1σ uncertainty for each axis. Needs jq. Usage:
#   scripts/roundtrip.sh [DURATION_S] [SEED] [Q N B K R]
# default 7200 s, seed 1, and the paper's Table 2 terms (X axis) on every axis.
set -euo pipefail
cd "$(dirname "$0")/.."
duration=${1:-7200}
seed=${2:-1}
Q=${3:-0.1663} N=${4:-0.95164} B=${5:-0.60565} K=${6:-0.07759} R=${7:-0.43223}
bin=build/bin/gyroctl
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Pure mode (no DLPF, no quantisation), so that what comes back is the Allan terms alone.
$bin simulate --quantization "$Q" --arw "$N" --bias-instability "$B" --rrw "$K" --rate-ramp "$R" --duration "$duration" --seed "$seed" -o "$work/sim.csv" 2>/dev/null
$bin analyze "$work/sim.csv" --no-detrend --json --write-model "$work/model.toml" >"$work/a.json"
$bin simulate --model "$work/model.toml" --duration "$duration" --seed $((seed + 1)) -o "$work/sim2.csv" 2>/dev/null
$bin analyze "$work/sim2.csv" --no-detrend --json >"$work/b.json"
printf '%-28s %4s %10s %12s %10s %12s\n' term axis in "fit(1)" "+-1sigma" "fit(2)"
for key in quantization_urad arw_deg_per_sqrt_h bias_instability_deg_per_h rrw_deg_per_h_sqrt_h rate_ramp_deg_per_h2; do
  case $key in
    quantization_urad) truth=$Q ;; arw_deg_per_sqrt_h) truth=$N ;;
    bias_instability_deg_per_h) truth=$B ;; rrw_deg_per_h_sqrt_h) truth=$K ;;
    rate_ramp_deg_per_h2) truth=$R ;;
  esac
  for axis in gx gy gz; do
    printf '%-28s %4s %10.5g %12.5g %10.3g %12.5g\n' "$key" "$axis" "$truth" \
      "$(jq ".axes.$axis.noise.$key" "$work/a.json")" "$(jq ".axes.$axis.noise_uncertainty.$key" "$work/a.json")" \
      "$(jq ".axes.$axis.noise.$key" "$work/b.json")"
  done
done
echo "fit(1): analyze of the simulation from the terms; fit(2): analyze of a simulation from fit(1)'s model file (--no-detrend, so the ramp stays)"
