#!/usr/bin/env bash
# Messages a user reads must not start with an internal name (issue 12 §5): a string literal in
# product code that begins with a camelCase or CamelCase identifier, a qualified name (a::b) or a
# call (f()) followed by ": ", or a use of __func__, fails this test (ctest: message_names).
# Comment lines are skipped; a literal such as "SIGHUP: " or "gyrod: " (one word, no inner
# capital) is a word a user knows and passes.
# Usage: check-message-names.sh SOURCE_DIR
set -euo pipefail
root=${1:?usage: check-message-names.sh SOURCE_DIR}
ident='[A-Za-z_][A-Za-z0-9_]*'
camel='[a-z][a-z0-9_]*[A-Z][A-Za-z0-9_]*'   # yuleWalker, fitLinearTrend
pascal='[A-Z][a-z0-9_]+[A-Z][A-Za-z0-9_]*'  # EventLoop, RollingOverlappingAllan
qualified="$ident(::$ident)+"               # portable::log, EventLoop::addFd
name="($camel|$pascal|$qualified|$ident\\(\\))(\\(\\))?"
# "name: ..." or "Class::" + method: the literal's first characters are the name.
pattern="\"$name: |\"$ident::\"|\\b__func__\\b|__FUNCTION__|__PRETTY_FUNCTION__"
status=0
for dir in processing formats protocol driver daemon tools; do
  [ -d "$root/$dir" ] || continue
  while IFS= read -r hit; do
    echo "$hit" >&2
    status=1
  done < <(grep -rnE --include='*.cpp' --include='*.hpp' --include='*.h' --include='*.c' "$pattern" "$root/$dir" |
    grep -vE '^[^:]+:[0-9]+:[[:space:]]*(//|/\*|\*)' || true)
done
if [ "$status" != 0 ]; then
  echo "message_names: the lines above start a message with an internal name; say what is computed in a" \
    "user's words (\"the AR model fit needs ...\") and what is wrong with which value" >&2
fi
exit "$status"
