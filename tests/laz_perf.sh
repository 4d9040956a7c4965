#!/usr/bin/env bash
# A second, independent LAZ decoder: every LAZ of items version 2 or 3 in ../shared/data (laz-perf
# reads no version 1) converted to LAS by lodforge, then decoded by npm's laz-perf (LASzip in
# WebAssembly) and compared record for record. Fails on any difference.
set -euo pipefail
lodforge=$1 data=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
[[ -d $here/js/node_modules/laz-perf ]] || { echo "laz-perf is not installed: run scripts/install-deps.sh" >&2; exit 1; }
rm -rf "$out" && mkdir -p "$out"
count=0
for laz in "$data"/points/*.laz; do
  if "$lodforge" info "$laz" | grep -q ' v1\b'; then continue; fi
  name=$(basename "${laz%.laz}")
  "$lodforge" -q convert "$laz" -o "$out/$name.las"
  node "$here/js/laz-perf-compare.mjs" "$laz" "$out/$name.las"
  count=$((count + 1))
done
[[ $count -ge 2 ]] || { echo "expected at least 2 LAZ files of versions 2 and 3, found $count" >&2; exit 1; }
