#!/usr/bin/env bash
# The include rule of docs/architecture.md: every project #include "..." in a layer names a
# layer it may use. An upward or sideways include fails this test (ctest: include_layers).
# Usage: check-include-layers.sh SOURCE_DIR
set -euo pipefail
root=${1:?usage: check-include-layers.sh SOURCE_DIR}
cd "$root"

# layer folder -> the folders its files may include from (its own first). Longest prefix wins,
# so driver/mock/ and each concern of processing/ have their own rows. Keep this table and
# docs/architecture.md's in step.
declare -A allowed=(
  [processing/base]="processing/base"
  [processing/allan]="processing/allan processing/base"
  [processing/paper]="processing/paper processing/allan processing/base"
  [processing/simulation]="processing/simulation processing/base"
  [processing/motion]="processing/motion processing/paper processing/allan processing/simulation processing/base"
  [processing/model_check]="processing/model_check processing/paper processing/allan processing/simulation processing/base"
  [processing/attitude]="processing/attitude processing/base"
  [processing]="processing"
  [formats]="formats processing"
  [protocol]="protocol processing"
  [driver]="driver protocol/fd.hpp"
  [driver/mock]="driver/mock driver processing protocol/fd.hpp"
  [daemon]="daemon driver protocol formats processing"
  [tools]="tools protocol formats processing"
  [bench]="bench daemon driver protocol formats processing tools"
)

layer_of() {
  local path=$1
  case $path in
    driver/mock/*) echo driver/mock ;;
    processing/*/*) local rest=${path#processing/}; echo "processing/${rest%%/*}" ;;
    *) echo "${path%%/*}" ;;
  esac
}

violations=0
checked=0
while IFS= read -r file; do
  layer=$(layer_of "$file")
  if [[ -z ${allowed[$layer]+x} ]]; then
    # A new folder needs its row (and its arrows in docs/architecture.md) before it has code.
    echo "$file: layer '$layer' has no row in the include rule (tests/architecture/check-include-layers.sh)" >&2
    violations=$((violations + 1))
    continue
  fi
  checked=$((checked + 1))
  while IFS=: read -r line target; do
    ok=0
    for prefix in ${allowed[$layer]}; do
      if [[ $prefix == *.hpp ]]; then
        [[ $target == "$prefix" ]] && ok=1
      elif [[ $target == "$prefix"/* ]]; then
        # driver/ may not reach into driver/mock/: the real driver knows no mock.
        if [[ $layer == driver && $target == driver/mock/* ]]; then ok=0; else ok=1; fi
      fi
      [[ $ok == 1 ]] && break
    done
    if [[ $ok == 0 ]]; then
      echo "$file:$line: layer '$layer' may not include \"$target\" (allowed: ${allowed[$layer]})" >&2
      violations=$((violations + 1))
    fi
  done < <(grep -n -E '^[[:space:]]*#[[:space:]]*include[[:space:]]+"' "$file" |
           sed -E 's/^([0-9]+):[[:space:]]*#[[:space:]]*include[[:space:]]+"([^"]+)".*/\1:\2/')
done < <(find processing formats protocol driver daemon tools bench -type f \
           \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) 2>/dev/null | sort)

if [[ $checked -eq 0 ]]; then
  echo "check-include-layers: no source files found under $root" >&2
  exit 1
fi
if [[ $violations -ne 0 ]]; then
  echo "check-include-layers: $violations include(s) break the layer rule (docs/architecture.md)" >&2
  exit 1
fi
echo "check-include-layers: $checked files follow the layer rule"
