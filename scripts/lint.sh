#!/usr/bin/env bash
# clang-tidy (.clang-tidy) over the product sources, using build/compile_commands.json.
# Usage: scripts/lint.sh [BUILD_DIR]   (after a build; exits non-zero on any warning)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
[ -f "$build/compile_commands.json" ] || { echo "lint: $build/compile_commands.json missing: configure with cmake first" >&2; exit 1; }
# The compile commands without the precompiled header (cmake/BuildSpeed.cmake): clang cannot read
# gcc's .gch, and each file is linted as written, with only the includes it names.
db=$(mktemp -d)
trap 'rm -rf "$db"' EXIT
sed -E 's# -Winvalid-pch##g; s# -include [^ ]*/cmake_pch\.hxx##g' "$build/compile_commands.json" >"$db/compile_commands.json"
mapfile -t files < <(git ls-files 'processing/*.cpp' 'formats/*.cpp' 'protocol/*.cpp' 'driver/*.cpp' 'daemon/*.cpp' 'tools/*.cpp')
printf '%s\n' "${files[@]}" | xargs -P "$(nproc)" -n 4 clang-tidy -p "$db" --quiet
echo "lint: ${#files[@]} product files clean under .clang-tidy"
