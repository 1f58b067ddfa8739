#!/usr/bin/env bash
# The fuzz targets are named in four places that must agree (ctest: fuzz_targets_listed):
# fuzz/targets.cmake, the table of docs/testing.md's "Fuzzing", scripts/fuzz.sh's -max_len
# table, and the seed corpora fuzz/corpus/TARGET/ (each with a fuzz/TARGET.cpp).
# Usage: check-targets.sh SOURCE_DIR
set -euo pipefail
cd "${1:?usage: check-targets.sh SOURCE_DIR}"
sorted() { tr ' ' '\n' | sed '/^$/d' | sort | tr '\n' ' '; }
cmake_list=$(sed -n 's/^set(GYROD_FUZZ_TARGETS \(.*\))$/\1/p' fuzz/targets.cmake | sorted)
docs_list=$(sed -n '/^## Fuzzing/,/^## /p' docs/testing.md | sed -n 's/^| `\([a-z_]*\)` |.*/\1/p' |
  tr '\n' ' ' | sorted)
script_list=$(sed -n 's/^declare -A max_len=(\(.*\))$/\1/p' scripts/fuzz.sh | grep -o '\[[a-z_]*\]' | tr -d '[]' |
  tr '\n' ' ' | sorted)
corpus_list=$(for d in fuzz/corpus/*/; do basename "$d"; done | tr '\n' ' ' | sorted)
status=0
for name in docs_list script_list corpus_list; do
  if [[ ${!name} != "$cmake_list" ]]; then
    echo "check-targets: $name '${!name}' differs from fuzz/targets.cmake's '$cmake_list'" >&2
    status=1
  fi
done
for target in $cmake_list; do
  [[ -f fuzz/$target.cpp ]] || { echo "check-targets: fuzz/$target.cpp is missing" >&2; status=1; }
done
[[ -n $cmake_list ]] || { echo "check-targets: no targets in fuzz/targets.cmake" >&2; status=1; }
((status == 0)) && echo "check-targets: $cmake_list agree"
exit $status
