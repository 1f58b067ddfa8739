#!/usr/bin/env bash
# docs/architecture.md's layer table and the include rule (check-include-layers.sh) name the same
# layers, and where the doc lists what a layer may include as folders, the same folders; every
# folder of processing/ has its row in both and is named in the README's layout section
# (ctest: architecture_doc).
# Usage: check-architecture-doc.sh SOURCE_DIR
set -euo pipefail
root=${1:?usage: check-architecture-doc.sh SOURCE_DIR}
cd "$root"
rule=tests/architecture/check-include-layers.sh
doc=docs/architecture.md
problems=0
fail() { echo "$1" >&2; problems=$((problems + 1)); }

# The rule's rows: [layer]="folders".
declare -A rule_rows=()
while IFS= read -r row; do
  layer=${row#*[}; layer=${layer%%]*}
  folders=${row#*=\"}; folders=${folders%\"*}
  rule_rows[$layer]=$folders
done < <(grep -E '^[[:space:]]*\[[a-z_/]+\]="[^"]*"' "$rule")
[[ ${#rule_rows[@]} -gt 0 ]] || { echo "check-architecture-doc: no rows read from $rule" >&2; exit 1; }

# The doc's rows: | `layer/` | library | what | may include |
declare -A doc_rows=()
while IFS= read -r line; do
  IFS='|' read -r _ first _ _ last _ <<<"$line"
  layer=$(sed -E 's/^[[:space:]]*`([a-z_/]+)\/`.*/\1/' <<<"$first")
  doc_rows[$layer]=$last
done < <(grep -E '^\| `[a-z_/]+/` \|' "$doc")

sorted() { tr ' ' '\n' | sed '/^$/d' | sort | tr '\n' ' '; }
for layer in "${!rule_rows[@]}"; do
  if [[ -z ${doc_rows[$layer]+x} ]]; then
    [[ $layer == processing ]] && continue  # the core's own row: its concerns are listed instead
    fail "$doc: no row for layer '$layer/' of $rule"
    continue
  fi
  cell=${doc_rows[$layer]}
  # Only a cell that is a plain list of `folder/` or `file.hpp` is compared; prose is not.
  if grep -qE '^[[:space:]]*(`[a-z_./]+`(, )?)+[[:space:]]*$' <<<"$cell"; then
    doc_list=$(grep -oE '`[a-z_./]+`' <<<"$cell" | tr -d '`' | sed -E 's#/$##' | sorted)
    rule_list=$(sorted <<<"${rule_rows[$layer]}")
    [[ $doc_list == "$rule_list" ]] ||
      fail "$doc: layer '$layer/' may include '$doc_list' there but '$rule_list' in $rule"
  fi
done
for layer in "${!doc_rows[@]}"; do
  [[ $layer == tests ]] && continue  # tests may include everything and are not checked
  [[ -n ${rule_rows[$layer]+x} ]] || fail "$doc: row '$layer/' has no row in $rule"
done
for dir in processing/*/; do
  dir=${dir%/}
  [[ -n ${rule_rows[$dir]+x} ]] || fail "$rule: no row for $dir"
  [[ -n ${doc_rows[$dir]+x} ]] || fail "$doc: no row for $dir/"
  sed -n '/^## Layout/,/^## /p' README.md | grep -qF "\`${dir#processing/}/\`" ||
    fail "README.md: the layout section does not name ${dir#processing/}/ (of processing/)"
done
if [[ $problems -ne 0 ]]; then
  echo "check-architecture-doc: $problems disagreement(s) between $doc, $rule and README.md" >&2
  exit 1
fi
echo "check-architecture-doc: ${#rule_rows[@]} layers agree between $doc and $rule"
