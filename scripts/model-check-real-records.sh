#!/usr/bin/env bash
# The model check on every real record the project ships (tests/data/mpu6050-*): per axis the
# effects named, the held-out Ljung–Box p, the share of the Allan curve in the replicas' 90 %
# band and the held-out innovation variance, base → extended. Prints the markdown table of
# docs/model-check.md ("Real records"); with --pin also writes the figures the test
# tests/tools/test_model_check_real_records.cpp holds the check to
# (tests/data/model-check-real-records.json). Uses build/bin/gyroctl (scripts/test.sh builds it).
#
#   scripts/model-check-real-records.sh [--pin]
set -euo pipefail
cd "$(dirname "$0")/.."
gyroctl=build/bin/gyroctl
[ -x "$gyroctl" ] || { echo "build/bin/gyroctl is missing: run scripts/test.sh first" >&2; exit 1; }
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
records=(mpu6050-arduino-100hz/imu_static_test.csv mpu6050-arduino-100hz/example_data_tinit_calc.csv
         mpu6050-sensor-fusion-set1/unmoved-x-pointing-forward.csv mpu6050-sensor-fusion-set1/unmoved-x-pointing-up.csv)
for r in "${records[@]}"; do
  src=tests/data/$r
  name=$(echo "$r" | tr '/' '_')
  in=$src
  if [[ $r == mpu6050-arduino-100hz/* ]]; then  # raw counts with a 5-line header: gyroctl import reads them
    in=$scratch/$name
    "$gyroctl" import "$src" -o "$in" >/dev/null 2>&1
  fi
  "$gyroctl" model-check "$in" --json >"$scratch/$name.json" 2>/dev/null
done
/usr/bin/python3 - "$scratch" "${1:-}" "$(git rev-parse --short HEAD 2>/dev/null || echo unknown)" "${records[@]}" <<'PY'
import json, sys
scratch, mode, commit, records = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
pinned = {"commit": commit, "records": []}
print("| record | axis | effects named | held-out Ljung–Box p | in 90 % band | held-out innovation var [(°/s)²] | passes |")
print("|---|---|---|---|---|---|---|")
passes = total = 0
for r in records:
    doc = json.load(open(f"{scratch}/{r.replace('/', '_')}.json"))
    entry = {"record": r, "axes": {}}
    for axis, a in doc["axes"].items():
        g = a["gain"]
        effects = sorted(e["effect"] for e in a["effects"])
        p, band = g["ljung_box_p_extended_held_out"], g["in_band_extended"]
        ok = p >= 0.01 and band >= 0.9
        passes += ok; total += 1
        entry["axes"][axis] = {"effects": effects, "ljung_box_p_held_out": p, "in_band": band, "passes": ok}
        print(f"| `{r.split('/')[1]}` | {axis} | {', '.join(effects) or '—'} | "
              f"{g['ljung_box_p_base_held_out']:.2g} → {p:.2g} | {g['in_band_base']:.0%} → {band:.0%} | "
              f"{g['innovation_var_base_held_out']:.4g} → {g['innovation_var_extended_held_out']:.4g} | "
              f"{'yes' if ok else 'no'} |")
    pinned["records"].append(entry)
print(f"\n{passes} of {total} axes pass (held-out Ljung–Box p ≥ 0.01 and ≥ 90 % in band); commit {commit}")
pinned["passing_axes"] = passes
if mode == "--pin":
    with open("tests/data/model-check-real-records.json", "w") as f:
        json.dump(pinned, f, indent=1)
        f.write("\n")
PY
