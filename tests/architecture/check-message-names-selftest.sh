#!/usr/bin/env bash
# The message-name checker must fail on each kind of internal name at the start of a literal
# and pass on user words, so that a green message_names test means something
# (ctest: message_names_selftest).
set -euo pipefail
checker=${1:?usage: check-message-names-selftest.sh CHECKER}
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

mkdir -p "$scratch"/{processing,daemon,tools}
cat > "$scratch/processing/a.cpp" <<'CPP'
// yuleWalker: a comment may name the function it is in.
void f() { throw std::invalid_argument("the AR model fit needs a series that varies"); }
void g() { spdlog::error("SIGHUP: keeping the running filter: {}", what); }
void h() { std::fprintf(stderr, "gyrod: %s\n", what); }
bool k(const std::string& n) { return n == "MemTotal:"; }
CPP
: > "$scratch/daemon/a.cpp"
: > "$scratch/tools/a.cpp"
"$checker" "$scratch" >/dev/null 2>&1 || { echo "selftest: a clean tree was rejected" >&2; exit 1; }

expect_rejected() {  # file, line, what the violation is
  local file=$1 line=$2 what=$3
  cp "$scratch/$file" "$scratch/$file.keep"
  printf '%s\n' "$line" >> "$scratch/$file"
  if "$checker" "$scratch" >/dev/null 2>&1; then
    echo "selftest: $what was not caught ($file: $line)" >&2
    exit 1
  fi
  mv "$scratch/$file.keep" "$scratch/$file"
}
expect_rejected processing/a.cpp 'throw std::invalid_argument("yuleWalker: the series has zero variance");' \
  "a camelCase function name"
expect_rejected daemon/a.cpp 'throw std::invalid_argument("EventLoop: empty timer callback");' "a class name"
expect_rejected daemon/a.cpp 'throw std::invalid_argument("EventLoop::addFd: fd 3 is not watched");' \
  "a qualified method name"
expect_rejected tools/a.cpp 'throw std::invalid_argument(std::string("Rolling::") + where + ": index");' \
  "a class prefix completed by a variable"
expect_rejected tools/a.cpp 'throw std::invalid_argument("parse(): bad value");' "a call"
expect_rejected processing/a.cpp 'throw std::invalid_argument(std::string(__func__) + ": bad");' "__func__"
echo "selftest: the checker passes user words and rejects 6 kinds of internal name"
