#!/usr/bin/env bash
# The include-rule checker must fail on an upward include and pass on a clean tree, so that
# a green include_layers test means something (ctest: include_layers_selftest).
set -euo pipefail
checker=${1:?usage: check-include-layers-selftest.sh CHECKER}
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

mkdir -p "$scratch"/{processing/base,processing/allan,processing/simulation,processing/motion,formats,driver/mock,daemon,tools}
printf '#include "processing/base/a.hpp"\n' > "$scratch/processing/b.cpp"
printf '#include "processing/base/a.hpp"\n' > "$scratch/processing/base/a.cpp"
printf '#include "processing/base/a.hpp"\n' > "$scratch/processing/allan/v.cpp"
printf '#include "processing/simulation/s.hpp"\n#include "processing/allan/v.hpp"\n' > "$scratch/processing/motion/r.cpp"
printf '#include "processing/a.hpp"\n#include "formats/f.hpp"\n' > "$scratch/formats/f.cpp"
printf '#include "driver/d.hpp"\n' > "$scratch/driver/d.cpp"
printf '#include "driver/d.hpp"\n#include "processing/a.hpp"\n' > "$scratch/driver/mock/m.cpp"
printf '#include "driver/d.hpp"\n#include "formats/f.hpp"\n' > "$scratch/daemon/g.cpp"
printf '#include "formats/f.hpp"\n' > "$scratch/tools/t.cpp"
"$checker" "$scratch" >/dev/null || { echo "selftest: a clean tree was rejected" >&2; exit 1; }

expect_rejected() {  # file, include line, what the violation is
  local file=$1 line=$2 what=$3
  cp "$scratch/$file" "$scratch/$file.keep"
  printf '%s\n' "$line" >> "$scratch/$file"
  if "$checker" "$scratch" 2>/dev/null >/dev/null; then
    echo "selftest: $what was not caught ($file: $line)" >&2
    exit 1
  fi
  mv "$scratch/$file.keep" "$scratch/$file"
}
expect_rejected processing/b.cpp '#include "driver/d.hpp"' "processing including the driver"
expect_rejected driver/d.cpp '#include "processing/a.hpp"' "the real driver including processing"
expect_rejected driver/d.cpp '#include "driver/mock/m.hpp"' "the real driver including the mock"
expect_rejected processing/base/a.cpp '#include "processing/allan/v.hpp"' "the core's base including a concern above it"
expect_rejected processing/allan/v.cpp '#include "processing/motion/r.hpp"' "Allan statistics including the motion estimators"
expect_rejected processing/allan/v.cpp '#include "processing/simulation/s.hpp"' "one concern including a sideways one"
expect_rejected daemon/g.cpp '#include "tools/x.hpp"' "the daemon including tools"
expect_rejected tools/t.cpp '#include "daemon/protocol.hpp"' "tools including the daemon"
expect_rejected formats/f.cpp '  #  include "daemon/y.hpp"' "an indented include"
# A folder of the core that the rule has no row for is refused, not skipped.
mkdir -p "$scratch/processing/unlisted"
printf '#include "processing/base/a.hpp"\n' > "$scratch/processing/unlisted/u.cpp"
if "$checker" "$scratch" 2>/dev/null >/dev/null; then
  echo "selftest: a folder without a row in the rule was not caught (processing/unlisted/u.cpp)" >&2
  exit 1
fi
rm -r "$scratch/processing/unlisted"
echo "selftest: the checker passes a clean tree, rejects 9 kinds of upward or sideways include and a folder without a row"
