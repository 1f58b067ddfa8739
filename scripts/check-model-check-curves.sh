#!/usr/bin/env bash
# ctest's smoke test of the detection-curve program (bench/model_check_curves.cpp): its --quick
# mode runs, and every table it prints parses (11 numbers per row: the check, the known form and
# the blind bound, fractions in [0, 1], lo ≤ p ≤ hi) with a summary line per curve and a
# clean-data line. No timing, no detection figures.
#   scripts/check-model-check-curves.sh PATH/TO/model_check_curves
set -euo pipefail
out=$("$1" --quick)
echo "$out"
echo "$out" | awk '
  /^# curve / { curves++; in_table = 1; next }
  /^#/ { next }
  /^summary / { summaries++; if (NF < 10 || $4 != "blind50" || $6 != "optimal50") { print "bad summary: " $0; bad++ } in_table = 0; next }
  /^clean / { cleans++; next }
  /^checks / { next }
  NF == 0 || /^model_check_curves:/ { next }
  in_table {
    rows++
    if (NF != 8 && NF != 11) { print "row without 8 or 11 fields: " $0; bad++; next }
    if (NF == 11) bounds++
    for (i = 1; i <= NF; i++) if ($i !~ /^[-+0-9.eE]+$/) { print "not a number: " $0; bad++; next }
    for (c = 3; c <= NF - 2; c += 3)
      if ($c < 0 || $c > 1 || $(c + 1) > $c + 1e-9 || $(c + 2) < $c - 1e-9) { print "bad fraction or interval: " $0; bad++ }
    next
  }
  { print "unexpected line: " $0; bad++ }
  END {
    if (curves < 5 || summaries != curves || cleans < 1 || rows < 2 * curves || bounds < rows) {
      printf "expected 5 curves with rows and summaries, the bound on every row, and a clean line; got %d curves, %d summaries, %d rows, %d with the bound, %d clean\n", curves, summaries, rows, bounds, cleans
      exit 1
    }
    exit bad > 0
  }'
