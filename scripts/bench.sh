#!/usr/bin/env bash
# `make bench`: kernel benchmarks, then the generators at growing sizes with wall time and peak
# memory from /usr/bin/time -v. BENCH_LARGE=1 adds the 1,000,000-object assembly and the
# 100,000,000-triangle scan (several GB of disk, a few minutes). Results go to stdout and
# build/bench/; docs/BENCHMARKS.md quotes them.
set -euo pipefail
cd "$(dirname "$0")/.."
lodforge=$(pwd)/build/release/lodforge
work=${BENCH_DIR:-build/bench}
mkdir -p "$work"

echo "== machine"
echo "$(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB, $(lscpu | sed -n 's/^Model name: *//p')"

echo
echo "== kernels (Google Benchmark)"
build/release/bench/bench_kernels --benchmark_min_time=0.5

measure() {  # name, then the command; prints a table row and removes the output file
  local name=$1; shift
  local log=$work/time.log
  /usr/bin/time -v "$@" > /dev/null 2> "$log" || { cat "$log"; exit 1; }
  local wall rss out
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$log")
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$log")
  out=$(du -h "${@: -1}" | cut -f1)
  printf '| %-44s | %9s | %8d MiB | %7s |\n' "$name" "$wall" $((rss / 1024)) "$out"
  rm -f "${@: -1}"
}

echo
echo "== generators (wall time, peak RSS, output size)"
printf '| %-44s | %9s | %12s | %7s |\n' command wall "peak RSS" output
printf '|%s|%s|%s|%s|\n' "$(printf -- '-%.0s' {1..46})" "-----------" "--------------" "---------"
sizes_cad=(10K 100K)
sizes_scan=(1M 10M)
if [[ ${BENCH_LARGE:-0} == 1 ]]; then sizes_cad+=(1M); sizes_scan+=(100M); fi
for n in "${sizes_cad[@]}"; do
  measure "generate cad --objects $n (PLY)" "$lodforge" -q generate cad --objects "$n" -o "$work/cad.ply"
done
measure "generate cad --objects 10K (GLB)" "$lodforge" -q generate cad --objects 10K -o "$work/cad.glb"
for n in "${sizes_scan[@]}"; do
  measure "generate scan --triangles $n" "$lodforge" -q generate scan --triangles "$n" -o "$work/scan.ply"
done
measure "generate points --points 10M" "$lodforge" -q generate points --points 10M -o "$work/points.ply"
