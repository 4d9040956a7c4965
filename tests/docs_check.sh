#!/usr/bin/env bash
# The docs name only what exists (tests/js/docs-check.mjs): every path, name of the code and
# option that README.md and docs/*.md give in backticks, checked against the tree, the sources
# and `lodforge … --help`. Then the check is shown able to fail: a copy of docs/tiles.md with a
# wrong function, path and option planted in it must be reported at exactly their lines, exit 1.
set -euo pipefail
lodforge=$1
here=$(cd "$(dirname "$0")" && pwd)
check=$here/js/docs-check.mjs
node "$check" "$lodforge"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source_page=$here/../docs/tiles.md
page=$tmp/tiles.md
# After the first blank line past the page's middle that is outside a fenced block.
at=$(awk -v half=$(( $(wc -l < "$source_page") / 2 )) \
  '/^(```|~~~)/ { fenced = !fenced } NR > half && !fenced && /^$/ { print NR; exit }' "$source_page")
[[ -n $at ]] || { echo "docs_check: no blank line to plant after in $source_page" >&2; exit 1; }
{
  head -n "$at" "$source_page"
  echo 'Planted: `noSuchFunctionXyz` and `simplify/no_such_file.cpp`, and a command'
  echo 'further down, `lodforge tiles IN -o OUT --no-such-option`.'
  echo
  tail -n +"$((at + 1))" "$source_page"
} > "$page"
expected="$page:$((at + 1)): \`noSuchFunctionXyz\` names nothing in the code
$page:$((at + 1)): \`simplify/no_such_file.cpp\` names no file in the tree
$page:$((at + 2)): \`--no-such-option\` is no option of \`lodforge tiles\`"
if found=$(node "$check" "$lodforge" "$page" 2> "$tmp/summary"); then
  echo "docs_check: the check passed a page with planted wrong names" >&2
  exit 1
fi
if [[ $found != "$expected" ]]; then
  echo "docs_check: the planted wrong names were not reported as expected:" >&2
  diff <(echo "$expected") <(echo "$found") >&2 || true
  exit 1
fi
echo "docs_check: the planted wrong names are reported, exit 1:"
echo "$found"
