#!/usr/bin/env bash
# Checks that the man pages name exactly what the programs define:
#   gyrod(8)      options            vs `gyrod --help`
#   gyroctl(1)    commands, options  vs `gyroctl --help` and `gyroctl COMMAND --help`
#   gyrod.toml(5) tables and keys    vs what gyrod's configuration loader accepts, found by
#                 asking the binary: an unknown name makes it list the valid ones
#                 ("valid sections: ...", "valid keys: ..."), table by table, sub-tables included.
# A key or option added to the program and not to its man page (or the reverse) fails here.
# The man pages' convention (see their headers): a documented option or key is a .TP item
# whose first line is .B/.BI/.BR naming it; gyroctl's commands and gyrod.toml's tables are .SS.
# The bash completions (completion/) must offer the same commands and options. The configuration
# keys that README.md and docs/ name exist, and config/gyrod.toml shows every key.
# Usage: check-man-pages.sh SOURCE_DIR GYROD GYROCTL
# GYROD_TEST_LAUNCHER (e.g. "qemu-aarch64-static -L SYSROOT") runs a cross build's binaries.
set -euo pipefail
man_dir=$1/man completion_dir=$1/completion
read -r -a launcher <<<"${GYROD_TEST_LAUNCHER:-}"
gyrod_bin=$2 gyroctl_bin=$3
run_gyrod() { "${launcher[@]}" "$gyrod_bin" "$@"; }
run_gyroctl() { "${launcher[@]}" "$gyroctl_bin" "$@"; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

# The option names (without dashes) of a --help text, one per line: the first --name of each
# option line (continuation lines such as "Excludes: --bias" follow the first option).
help_options() { sed -nE 's/^ +(-[A-Za-z],)?--([a-z0-9-]+).*/\2/p' | grep -vx help | sort -u; }

# From roff on stdin: "SECTION<TAB>NAME" for the first name of every .TP item's first line, where
# SECTION is the current .SS heading (after the .SH named $1; empty before any .SS).
# $2 = "option" takes \-\-name tokens, "key" the first word of .B.
roff_items() {
  awk -v want_sh="$1" -v kind="$2" '
    /^\.SH / { in_sh = (want_sh == "" || $0 ~ ("^\\.SH " want_sh "$")); ss = ""; next }
    !in_sh { next }
    /^\.SS / { ss = $0; sub(/^\.SS +/, "", ss); gsub(/"/, "", ss); gsub(/\\-/, "-", ss); next }
    /^\.TP/ { tp = 1; next }
    tp && /^\.B[IR]? / {
      tp = 0; line = $0; gsub(/\\-/, "-", line)
      if (kind == "option") {
        if (match(line, /--[a-z0-9-]+/)) { name = substr(line, RSTART + 2, RLENGTH - 2); if (name != "help") print ss "\t" name }
      } else { split(line, w, " "); print ss "\t" w[2] }
      next
    }
    { tp = 0 }'
}

compare() {  # compare LABEL PROGRAM_LIST MAN_LIST
  local missing extra
  missing=$(comm -23 "$2" "$3") extra=$(comm -13 "$2" "$3")
  if [ -n "$missing" ]; then
    echo "FAIL: $1: in the program, not in the file:"; echo "  ${missing//$'\n'/$'\n'  }"
    failures=$((failures + 1))
  fi
  if [ -n "$extra" ]; then
    echo "FAIL: $1: in the file, not in the program:"; echo "  ${extra//$'\n'/$'\n'  }"
    failures=$((failures + 1))
  fi
  if [ -z "$missing$extra" ]; then echo "ok: $1 ($(wc -l <"$2") names)"; fi
  return 0
}

# gyrod(8)
run_gyrod --help | help_options >"$work/gyrod.prog"
roff_items OPTIONS option <"$man_dir/gyrod.8" | cut -f2 | sort -u >"$work/gyrod.man"
compare "gyrod(8) options" "$work/gyrod.prog" "$work/gyrod.man"

# gyroctl(1): commands, then each command's options as "command --option".
run_gyroctl --help | awk '/^Subcommands:/ { s = 1; next } s && /^  [a-z]/ { print $1 } s && /^$/ { s = 0 }' |
  sort -u >"$work/commands.prog"
roff_items COMMANDS option <"$man_dir/gyroctl.1" >"$work/gyroctl.items"
awk '/^\.SH COMMANDS$/ { c = 1; next } /^\.SH / { c = 0 } c && /^\.SS / { sub(/^\.SS +/, ""); gsub(/\\-/, "-"); print }' \
  "$man_dir/gyroctl.1" | sort -u >"$work/commands.man"
compare "gyroctl(1) commands" "$work/commands.prog" "$work/commands.man"
: >"$work/gyroctl.prog"
while read -r command; do
  run_gyroctl "$command" --help | help_options | sed "s/^/$command --/" >>"$work/gyroctl.prog"
done <"$work/commands.prog"
sort -u -o "$work/gyroctl.prog" "$work/gyroctl.prog"
awk -F'\t' '{ print $1 " --" $2 }' "$work/gyroctl.items" | sort -u >"$work/gyroctl.man"
compare "gyroctl(1) options" "$work/gyroctl.prog" "$work/gyroctl.man"

# The completions: gyrod's option list, gyroctl's commands and each command's options.
sed -nE 's/^ *local options="([^"]*)".*/\1/p' "$completion_dir/gyrod" | tr ' ' '\n' | sed -n 's/^--//p' |
  grep -vx help | sort -u >"$work/gyrod.completion"
compare "completion/gyrod options" "$work/gyrod.prog" "$work/gyrod.completion"
# shellcheck disable=SC1091
(source "$completion_dir/gyroctl" && sed -nE 's/^ *local commands="([^"]*)".*/\1/p' "$completion_dir/gyroctl" |
  tr ' ' '\n' | sort -u >"$work/commands.completion" &&
  while read -r command; do
    _gyroctl_options "$command" | tr ' ' '\n' | sed "s/^/$command /"
  done <"$work/commands.completion" | sort -u >"$work/gyroctl.completion")
compare "completion/gyroctl commands" "$work/commands.prog" "$work/commands.completion"
compare "completion/gyroctl options" "$work/gyroctl.prog" "$work/gyroctl.completion"

# gyrod.toml(5): ask gyrod for the valid names of each table, recursing into every key that
# is itself a table (an array of tables answers the same way).
valid_names() {  # valid_names TOML_TEXT -> the comma list of "valid sections|keys: ...", or nothing
  printf '%b' "$1" >"$work/probe.toml"
  # timeout and a private socket: should a probe ever be valid, gyrod would start serving.
  timeout 10 "${launcher[@]}" "$gyrod_bin" --config "$work/probe.toml" --backend mock --socket "$work/probe.sock" 2>&1 >/dev/null |
    sed -nE 's/.*\(valid (sections|keys): ([^)]*)\).*/\2/p' | tr ',' '\n' | tr -d ' ' || true
}
: >"$work/toml.prog"
: >"$work/tables.prog"
queue=$(valid_names '[zz_not_a_section]\n')
[ -n "$queue" ] || { echo "FAIL: gyrod did not list its configuration sections"; exit 1; }
while [ -n "$queue" ]; do
  table=$(printf '%s\n' "$queue" | head -1) queue=$(printf '%s\n' "$queue" | tail -n +2)
  echo "[$table]" >>"$work/tables.prog"
  for key in $(valid_names "[$table]\nzz_not_a_key = 1\n"); do
    printf '[%s]\t%s\n' "$table" "$key" >>"$work/toml.prog"
    if [ -n "$(valid_names "[$table.$key]\nzz_not_a_key = 1\n")" ]; then queue=$(printf '%s\n%s' "$queue" "$table.$key"); fi
    queue=$(printf '%s\n' "$queue" | sed '/^$/d')
  done
done
sort -u -o "$work/toml.prog" "$work/toml.prog"
sort -u -o "$work/tables.prog" "$work/tables.prog"
roff_items SECTIONS key <"$man_dir/gyrod.toml.5" | sort -u >"$work/toml.man"
cut -f1 "$work/toml.man" | sort -u >"$work/tables.man"
compare "gyrod.toml(5) tables" "$work/tables.prog" "$work/tables.man"
tr '\t' ' ' <"$work/toml.prog" >"$work/toml.prog.txt"
tr '\t' ' ' <"$work/toml.man" >"$work/toml.man.txt"
compare "gyrod.toml(5) keys" "$work/toml.prog.txt" "$work/toml.man.txt"

# README.md and docs/*.md name configuration keys as `table.key`, `[table] key` or in an
# indented example under a `[table]` line; every such name of one of gyrod's tables must be a
# key (or sub-table) gyrod accepts. Dotted names of other things (`counters.retries`,
# `np.loadtxt`, a model file's `[x.extra]`) do not start with one of gyrod's tables and are
# not checked; a bare `key` cannot be told from a JSON or model-file name and is not either.
sed -E 's/^\[([^]]*)\]\t(.*)$/\1.\2/' "$work/toml.prog" >"$work/names.prog"
sed -E 's/^\[(.*)\]$/\1/' "$work/tables.prog" >>"$work/names.prog"
sed -E 's/^\[(.*)\]$/\1/' "$work/tables.prog" >"$work/tables.plain"
for doc in "$1/README.md" "$1"/docs/*.md; do
  awk -v tables="$work/tables.plain" -v names="$work/names.prog" -v doc="${doc#"$1"/}" '
    BEGIN {
      while ((getline t <tables) > 0) table[t] = 1
      while ((getline n <names) > 0) known[n] = 1
    }
    function check(tbl, key) {
      if (key ~ /^(c|h|cpp|hpp|md|csv|toml|yaml|json|py|sh|txt|png|service|socket)$/) return  # a file name
      if ((tbl in table) && !((tbl "." key) in known)) print doc ":" FNR ": `" tbl "." key "` is not a gyrod configuration key"
    }
    # An indented example: "    [table]" then "    key = value" lines.
    /^    \[[a-z_.]+\] *$/ { block = $0; gsub(/[][ ]/, "", block); next }
    block != "" && /^    [a-z_0-9]+ *=/ { k = $0; sub(/^ +/, "", k); sub(/ *=.*/, "", k); check(block, k); next }
    block != "" && !/^    / { block = "" }
    {
      line = $0
      while (match(line, /`[^`]+`/)) {
        span = substr(line, RSTART + 1, RLENGTH - 2); line = substr(line, RSTART + RLENGTH)
        if (match(span, /^\[[a-z_.]+\] [a-z_0-9]+/)) {
          t = substr(span, 2, index(span, "]") - 2); k = substr(span, index(span, "]") + 2, RLENGTH - index(span, "]") - 1)
          check(t, k); continue
        }
        rest = span
        while (match(rest, /(^|[^A-Za-z0-9_.\/-])[a-z_]+(\.[a-z_0-9]+)+/)) {
          d = substr(rest, RSTART, RLENGTH); rest = substr(rest, RSTART + RLENGTH)
          sub(/^[^a-z_]/, "", d)
          if (rest ~ /^[A-Za-z0-9_\/-]/) continue  # part of a longer name (a path, a file.ext-like word)
          t = d; sub(/\.[a-z_0-9]+$/, "", t); k = substr(d, length(t) + 2)
          check(t, k)
        }
      }
    }' "$doc"
done >"$work/doc-keys.bad"
# docs/hardware.md's fixes are settings: a bare `snake_case` name there is a configuration key
# or a name gyrod prints (a counter, a reason: a quoted string in daemon/, driver/, protocol/).
cut -f2 "$work/toml.prog" | sort -u >"$work/key-names"
grep -noE '`[a-z]+_[a-z0-9_]+`' "$1/docs/hardware.md" | while IFS=: read -r line name; do
  name=${name//\`/}
  grep -qxF "$name" "$work/key-names" && continue
  grep -rqF "\"$name\"" "$1/daemon" "$1/driver" "$1/protocol" && continue
  echo "docs/hardware.md:$line: \`$name\` is neither a configuration key nor a name gyrod prints"
done >>"$work/doc-keys.bad"
if [ -s "$work/doc-keys.bad" ]; then
  echo "FAIL: README.md and docs/ name configuration keys gyrod does not have:"; sed 's/^/  /' "$work/doc-keys.bad"
  failures=$((failures + 1))
else
  echo "ok: configuration keys named in README.md and docs/"
fi
# Every key gyrod accepts is documented in the configuration shipped with it (config/gyrod.toml,
# set or commented out under its table), besides gyrod.toml(5) above.
awk -v names="$work/toml.prog" '
  BEGIN { while ((getline n <names) > 0) { split(n, f, "\t"); want[f[1] "\t" f[2]] = 1 } }
  /^#? ?\[\[?[a-z_.]+\]\]?/ {  # a table, or a sub-table that shows its key of the table above
    t = $0; sub(/^# ?/, "", t); sub(/[ \t].*$/, "", t); gsub(/[][]/, "", t)
    if (t ~ /\./) { p = t; sub(/\.[^.]*$/, "", p); have["[" p "]\t" substr(t, length(p) + 2)] = 1 }
    if ($0 !~ /^#/) tbl = "[" t "]"
    next
  }
  /^#? ?[a-z_0-9]+ *=/ {
    k = $0; sub(/^# ?/, "", k); sub(/ *=.*/, "", k); have[tbl "\t" k] = 1
    # An inline table (or an array of them) shows the keys of the sub-table: k = [{ a = 1, b = 2 }].
    rest = $0; sub(/^[^=]*=/, "", rest)
    if (rest ~ /\{/) {
      subtable = tbl; sub(/\]$/, "." k "]", subtable)
      while (match(rest, /[{,] *[a-z_0-9]+ *=/)) {
        inner = substr(rest, RSTART + 1, RLENGTH - 1); rest = substr(rest, RSTART + RLENGTH)
        gsub(/[ =]/, "", inner); have[subtable "\t" inner] = 1
      }
    }
  }
  END { for (w in want) if (!(w in have)) { split(w, f, "\t"); print f[1] " " f[2] } }' "$1/config/gyrod.toml" |
  sort >"$work/config-keys.missing"
if [ -s "$work/config-keys.missing" ]; then
  echo "FAIL: config/gyrod.toml does not show these keys:"; sed 's/^/  /' "$work/config-keys.missing"
  failures=$((failures + 1))
else
  echo "ok: config/gyrod.toml shows every configuration key"
fi

[ "$failures" -eq 0 ] || { echo "check-man-pages: $failures mismatch(es)"; exit 1; }
