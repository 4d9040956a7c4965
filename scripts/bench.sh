#!/usr/bin/env bash
# `make bench`: kernel benchmarks, then the generators at growing sizes with wall time and peak
# memory from /usr/bin/time -v. BENCH_LARGE=1 adds the 1,000,000-object assembly and the
# 100,000,000-triangle scan (several GB of disk, a few minutes). Results go to stdout and
# build/bench/; docs/BENCHMARKS.md quotes them. BENCH_ONLY=simplify, runtime, render, tiles, points, laz, potree, surface, surface-closed, surface-tiles, cad, instances, textures, textured-obj, texture-formats, gltfpack, serve, tile-error, implicit, billion or distributed runs
# only that part. BENCH_LARGE=1 also runs the runtime on the 718,000-part assembly of the CAD
# paper's Table 1 (about 26 GB of disk and 8 minutes).
set -euo pipefail
cd "$(dirname "$0")/.."
lodforge=$(pwd)/build/release/lodforge
work=${BENCH_DIR:-build/bench}
mkdir -p "$work"

echo "== machine"
echo "$(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB, $(lscpu | sed -n 's/^Model name: *//p')"

echo
if [[ -z ${BENCH_ONLY:-} ]]; then
  echo "== kernels (Google Benchmark)"
  build/release/bench/bench_kernels --benchmark_min_time=0.5
fi

missing_peer() {  # VARIABLE name; true (after saying so) when $VARIABLE is no executable
  local variable=$1 name=$2
  [[ -n ${!variable:-} && -x ${!variable:-} ]] && return 1
  echo "$variable is not set to a $name binary: nothing to compare against (skipped)"
}
timed() {  # command...; prints "seconds peak-KiB" from /usr/bin/time -v
  local log=$work/time.log
  /usr/bin/time -v "$@" > /dev/null 2> "$log" || { tail -20 "$log" >&2; exit 1; }
  seconds_and_kib "$log"
}
seconds_and_kib() {  # a /usr/bin/time -v log; prints "seconds peak-KiB"
  local wall
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$1")
  echo "$(awk -F: '{ s = 0; for (i = 1; i <= NF; ++i) s = s * 60 + $i; print s }' <<< "$wall")" \
    "$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$1")"
}
measure() {  # name, then the command; prints a table row and removes the output file (the last argument)
  local name=$1; shift
  local log=$work/time.log
  /usr/bin/time -v "$@" > /dev/null 2> "$log" || { cat "$log"; exit 1; }
  local wall rss out
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$log")
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$log")
  out=$(du -h "${@: -1}" | cut -f1)
  printf '| %-44s | %9s | %8d MiB | %7s |\n' "$name" "$wall" $((rss / 1024)) "$out"
  [[ -n ${KEEP_OUTPUT:-} ]] || rm -f "${@: -1}"
}

if [[ -n ${BENCH_ONLY:-} ]]; then skip_generators=1; fi

runtime_section() {
  echo
  echo "== runtime: LOD selection and coherent streaming along orbit and fly-through paths (lodforge bench)"
  # A tenth of the paper's assembly with budgets scaled alike; BENCH_LARGE adds the full size.
  "$lodforge" -q generate cad --objects 71800 --detail 1.5 -o "$work/cad72k.ply"
  "$lodforge" -q build "$work/cad72k.ply" -o "$work/cad72k.lfp"
  rm -f "$work/cad72k.ply"
  for path in orbit fly; do
    "$lodforge" bench "$work/cad72k.lfp" --path "$path" --budget 300K,1.05M,1.8M --json "$work/bench-72k-$path.json"
  done
  # Table 1's OpenGL column: the same budgets drawn headless (llvmpipe: CPU times), fewer frames.
  "$lodforge" bench "$work/cad72k.lfp" --path orbit --frames 20 --budget 300K,1.05M,1.8M --render --json "$work/bench-72k-render.json"
  rm -f "$work/cad72k.lfp"
  if [[ ${BENCH_LARGE:-0} == 1 ]]; then
    "$lodforge" -q generate cad --objects 718K --detail 1.5 -o "$work/cad718k.ply"
    KEEP_OUTPUT=1 measure "build cad718k.ply (718,000 parts, 330 M triangles)" "$lodforge" -q build "$work/cad718k.ply" -o "$work/cad718k.lfp"
    rm -f "$work/cad718k.ply"
    for path in orbit fly; do
      "$lodforge" bench "$work/cad718k.lfp" --path "$path" --budget 3M,10.5M,18M -v --json "$work/bench-718k-$path.json"
    done
    rm -f "$work/cad718k.lfp"
  fi
}
if [[ ${BENCH_ONLY:-} == runtime ]]; then runtime_section; exit 0; fi

render_section() {
  echo
  echo "== rendering: two-pass versus first pass only against the full-detail render (bench_render, Fig. 7)"
  local data=${LODFORGE_DATA:-../shared/data}
  [[ -d $data ]] || data=/work/shared/data
  "$lodforge" -q generate cad --objects 2000 -o "$work/cad2k.ply"
  "$lodforge" -q build "$work/cad2k.ply" -o "$work/cad2k.lfp"
  local packages=("$work/cad2k.lfp@fly" "$work/cad2k.lfp@orbit")
  for model in 2CylinderEngine as1_motor Motor-c; do
    "$lodforge" -q build "$data/meshes/$model.glb" -o "$work/$model.lfp"
    packages+=("$work/$model.lfp@orbit")
  done
  "$lodforge" -q build "$data/meshes/horse.ply" -o "$work/horse.lfp"
  packages+=("$work/horse.lfp@orbit")
  # A textured scan (issue 36): 2 M triangles, 16 atlases of 4K, drawn with its textures.
  mkdir -p "$work/texscan"
  "$lodforge" -q generate scan --triangles 2M --texture 4K --atlases 16 -o "$work/texscan/scan.ply"
  local built
  built=$(timed "$lodforge" -q build "$work/texscan/scan.ply" -o "$work/texscan.lfp")
  echo "textured build (2 M triangles, 16 x 4K): ${built% *} s, $((${built#* } / 1024)) MiB peak, package $(du -h "$work/texscan.lfp" | cut -f1)"
  packages+=("$work/texscan.lfp@orbit")
  build/release/bench/bench_render --pictures "$work/pictures" "${packages[@]}"
  echo "(side-by-side pictures at 5 %: $work/pictures)"
  rm -rf "$work/cad2k.ply" "$work/texscan"
}
if [[ ${BENCH_ONLY:-} == render ]]; then render_section; exit 0; fi

simplify_section() {
  echo
  echo "== progressive build versus meshoptimizer (bench_simplify, best of 5 runs; 1 run above 5 M triangles)"
  local data=${LODFORGE_DATA:-../shared/data}
  [[ -d $data ]] || data=/work/shared/data
  "$lodforge" -q generate scan --triangles 97K -o "$work/scan97k.ply"
  "$lodforge" -q generate scan --triangles 10M -o "$work/scan10m.ply"
  "$lodforge" -q generate cad --objects 100K -o "$work/cad100k.ply"
  build/release/bench/bench_simplify --quality "$work/scan97k.ply" "$data"/meshes/stanford-bunny.obj \
    "$data"/meshes/horse.ply "$data"/meshes/2CylinderEngine.glb "$data"/meshes/as1_motor.glb \
    "$data"/meshes/Motor-c.glb "$work/scan10m.ply"
  build/release/bench/bench_simplify "$work/cad100k.ply"
  echo
  echo "== lodforge build: wall time and peak RSS (1 and 2 threads)"
  printf '| %-44s | %9s | %12s | %7s |\n' command wall "peak RSS" output
  printf '|%s|%s|%s|%s|\n' "$(printf -- '-%.0s' {1..46})" "-----------" "--------------" "---------"
  for input in scan10m cad100k; do
    for threads in 1 2; do
      measure "build $input.ply --threads $threads" "$lodforge" -q --threads "$threads" build "$work/$input.ply" -o "$work/$input.lfp"
    done
  done
  "$lodforge" -q build "$work/cad100k.ply" -o "$work/cad100k.lfp"
  "$lodforge" info "$work/cad100k.lfp" | grep -E "LOD data|triangles|vertices"
  rm -f "$work"/scan97k.ply "$work"/scan10m.ply "$work"/cad100k.ply "$work"/cad100k.lfp
  if [[ ${BENCH_LARGE:-0} == 1 ]]; then
    "$lodforge" -q generate cad --objects 1M -o "$work/cad1m.ply"
    measure "build cad1m.ply (1,000,000 parts, streamed)" "$lodforge" -q build "$work/cad1m.ply" -o "$work/cad1m.lfp"
    rm -f "$work/cad1m.ply"
  fi
}

# One row of the tiles table: label, mode, then the command after `lodforge`.
tiles_row() {
  local label=$1 mode=$2 log=$work/time.log
  shift 2
  /usr/bin/time -v "$lodforge" "$@" > "$work/tiles.out" 2> "$log" || { cat "$log"; exit 1; }
  local wall rss rate size
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$log")
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$log")
  rate=$(sed -n 's/.*(\([0-9,]*\) input triangles\/s).*/\1/p' "$work/tiles.out")
  size=$(du -sh "$work/tiles-out" | cut -f1)
  printf '| %-5s | %-22s | %9s | %5d MiB | %14s | %8s |\n' "$label" "$mode" "$wall" $((rss / 1024)) "$rate" "$size"
  grep -o "left out [1-9][0-9,]* small segments" "$log" || true
  rm -rf "$work/tiles-out"
}

tiles_section() {
  echo
  echo "== lodforge tiles: generated scans in each memory mode (the large-meshes paper's Table 2 / Fig. 10)"
  printf '| %-5s | %-22s | %9s | %9s | %14s | %8s |\n' scan mode wall "peak RSS" "input tri/s" tileset
  printf '|%s|%s|%s|%s|%s|%s|\n' ------- ------------------------ ----------- ----------- ---------------- ----------
  local sizes=(1M 10M)
  [[ ${BENCH_LARGE:-0} == 1 ]] && sizes+=(100M)
  for n in "${sizes[@]}"; do
    "$lodforge" -q generate scan --triangles "$n" -o "$work/tiles-scan.ply"
    for mode in minimal moderate unbounded; do
      tiles_row "$n" "$mode" -v tiles "$work/tiles-scan.ply" -o "$work/tiles-out" --memory "$mode"
      if [[ $mode == moderate ]]; then
        tiles_row "$n" "moderate --threads 2" -v --threads 2 tiles "$work/tiles-scan.ply" \
          -o "$work/tiles-out"
      fi
    done
    rm -f "$work/tiles-scan.ply"
  done
  # An assembly: parts are segments (whole when small), parents leave the smallest out.
  "$lodforge" -q generate cad --objects 100K -o "$work/tiles-cad.ply"
  tiles_row cad "moderate --threads 2" -v --threads 2 tiles "$work/tiles-cad.ply" -o "$work/tiles-out"
  rm -f "$work/tiles-cad.ply"
}
if [[ ${BENCH_ONLY:-} == tiles ]]; then tiles_section; exit 0; fi

# Point clouds (issue 7): lodforge points on generated clouds (streamed binary PLY with normals
# and colours, and the same cloud without normals, so they are estimated), peak RSS flat as the
# input grows; then the gaze-driven runtime along an orbit and the point tileset.
points_row() {
  local label=$1 mode=$2 log=$work/time.log
  shift 2
  /usr/bin/time -v "$lodforge" "$@" > "$work/points.out" 2> "$log" || { cat "$log"; exit 1; }
  local wall rss rate
  wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$log")
  rss=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$log")
  rate=$(sed -n 's/.*(\([0-9,]*\) points\/s).*/\1/p' "$work/points.out")
  printf '| %-5s | %-28s | %9s | %6d MiB | %12s | %s\n' "$label" "$mode" "$wall" $((rss / 1024)) "$rate" \
    "$(grep -o "streamed split passes\|[0-9]* streamed split passes" "$log" | head -1)"
}

points_section() {
  echo
  echo "== lodforge points: generated clouds (the points paper §4.1; PotreeConverter 2 publishes ~6 M points/s on 8 cores)"
  printf '| %-5s | %-28s | %9s | %10s | %12s | %s\n' cloud build wall "peak RSS" "points/s" passes
  printf '|%s|%s|%s|%s|%s|%s\n' ------- ------------------------------ ----------- ------------ -------------- ------
  local sizes=(1M 10M)
  [[ ${BENCH_LARGE:-0} == 1 ]] && sizes+=(100M)
  for n in "${sizes[@]}"; do
    "$lodforge" -q generate points --points "$n" -o "$work/points.ply"
    points_row "$n" "normals from the input" -v points "$work/points.ply" -o "$work/cloud.lfc"
    points_row "$n" "--memory-limit 256M" -v --memory-limit 256M points "$work/points.ply" -o "$work/cloud.lfc"
    if [[ $n != 100M ]]; then
      # Positions only (x y z text): normals are estimated.
      python3 - "$work/points.ply" "$work/points.xyz" <<'PY'
import struct, sys
src, dst = sys.argv[1], sys.argv[2]
with open(src, 'rb') as f:
    header = b''
    while not header.endswith(b'end_header\n'):
        header += f.readline()
    count = int([l for l in header.split(b'\n') if l.startswith(b'element vertex')][0].split()[2])
    props = [l.split()[-1] for l in header.split(b'\n') if l.startswith(b'property')]
    size = 28 if b'red' in props else 24
    with open(dst, 'w') as out:
        for _ in range(count):
            x, y, z = struct.unpack_from('<3f', f.read(size))
            out.write(f'{x:.4f} {y:.4f} {z:.4f}\n')
PY
      points_row "$n" "text x y z, normals estimated" -v points "$work/points.xyz" -o "$work/cloud2.lfc"
      rm -f "$work/points.xyz" "$work/cloud2.lfc"
      rm -rf "$work/cloud2.lfs"
    fi
    if [[ $n == 10M ]]; then
      echo
      "$lodforge" info "$work/cloud.lfc" | sed 's/^/    /'
      echo
      "$lodforge" bench "$work/cloud.lfc" --frames 120 --size 1280x720 --fovea 100,200,400 --render
      echo
      points_row "$n" "tiles (point tileset)" -v tiles "$work/points.ply" -o "$work/points-tiles"
      du -sh "$work/points-tiles" | sed 's/^/    tileset size: /'
      rm -rf "$work/points-tiles"
    fi
    rm -rf "$work/points.ply" "$work/cloud.lfc" "$work/cloud.lfs"
  done
}
if [[ ${BENCH_ONLY:-} == points ]]; then points_section; exit 0; fi

# lodforge serve under load (issue 8): wrk on loopback, 100 connections for 10 s, each request
# the next tile of a 1 M-triangle scan's tileset; then the same for tileset.json with gzip.
serve_section() {
  echo
  echo "== lodforge serve under wrk (loopback, 2 wrk threads, 100 connections, 10 s)"
  "$lodforge" -q generate scan --triangles 1M -o "$work/serve-scan.ply"
  rm -rf "$work/serve-tiles"
  "$lodforge" -q tiles "$work/serve-scan.ply" -o "$work/serve-tiles"
  (cd "$work/serve-tiles" && ls tiles/*.glb | sed 's|^|/tiles/|') > "$work/tiles.txt"
  local sizes
  sizes=$(du -b "$work"/serve-tiles/tiles/*.glb | awk '{s += $1} END {printf "%.0f KiB mean over %d tiles", s / NR / 1024, NR}')
  "$lodforge" serve "$work/serve-tiles" --port 18731 > "$work/serve.out" 2> "$work/serve.log" &
  local server=$!
  sleep 1
  echo "tile contents: $sizes"
  TILES_LIST="$work/tiles.txt" wrk -t2 -c100 -d10s --latency -s bench/wrk-tiles.lua \
    http://127.0.0.1:18731 | grep -E "Requests/sec|Transfer/sec|99%|50%|errors|requests in"
  echo "tileset.json, gzip:"
  wrk -t2 -c100 -d10s --latency -H "Accept-Encoding: gzip" http://127.0.0.1:18731/tiles/tileset.json |
    grep -E "Requests/sec|Transfer/sec|99%|50%|requests in|Non-2xx|Socket errors"
  kill -INT $server
  wait $server
  rm -rf "$work/serve-tiles" "$work/serve-scan.ply" "$work/tiles.txt"
}
if [[ ${BENCH_ONLY:-} == serve ]]; then serve_section; exit 0; fi

laz_section() {
  echo
  echo "== LAZ decoding: records per second, one thread and all, beside the same points as LAS (bench_laz)"
  # The LAZ files of the data folder, and any more named in LAZ_FILES (space-separated paths).
  # shellcheck disable=SC2086
  build/release/bench/bench_laz ${LAZ_FILES:+$(ls ${LODFORGE_DATA:-../shared/data}/points/*.laz) $LAZ_FILES}
}
if [[ ${BENCH_ONLY:-} == laz ]]; then laz_section; exit 0; fi

# Point tiles beside PotreeConverter 2 (issue 18), in one run on the same inputs: POTREE names
# its binary (built outside the project from its public source); LAZ_COMPRESS a command
# `LAZ_COMPRESS IN.las OUT.laz` that writes the same points as LAZ (lodforge writes no LAZ;
# e.g. a LASzip-based compressor). POTREE_SIZES (default "1M 20M") picks the clouds, kept in
# the bench folder as cloud-N.las/.laz for the next run; POTREE_RUNS (default 3) runs of each
# tool alternate and the median wall time is shown (this machine is shared and noisy).
# OLD_LODFORGE names another lodforge binary (an earlier build) run alternately beside them, so a
# change is measured against both in one run.
potree_once() {  # tool, input; prints "seconds peak-KiB output-size"
  local tool=$1 input=$2 out=$work/potree-out
  rm -rf "$out"
  local cmd
  case $tool in
    lodforge) cmd=("$lodforge" -q tiles "$input" -o "$out") ;;
    lodforge-old) cmd=("$OLD_LODFORGE" -q tiles "$input" -o "$out") ;;
    *) cmd=("$POTREE" "$input" -o "$out") ;;
  esac
  # Every run starts with nothing dirty in the page cache: the last run's pages still being
  # written back held the next one's writes to the disk's speed (3 s against 12 s, same binary).
  sync
  echo "$(timed "${cmd[@]}")" "$(du -sh "$out" | cut -f1)"
  rm -rf "$out"
}
potree_section() {
  echo
  echo "== point tiles beside PotreeConverter 2 (same input, one run; $(nproc) threads each; median of ${POTREE_RUNS:-3} alternating runs)"
  missing_peer POTREE PotreeConverter && return
  [[ -n ${LAZ_COMPRESS:-} ]] || echo "LAZ_COMPRESS is not set: LAS rows only"
  printf '| %-5s | %-4s | %-12s | %9s | %11s | %10s | %7s | %s\n' cloud file tool wall points/s "peak RSS" output "runs (s)"
  printf '|%s|%s|%s|%s|%s|%s|%s|%s\n' ------- ------ -------------- ----------- ------------- ------------ --------- ---------
  for n in ${POTREE_SIZES:-1M 20M}; do
    local las=$work/cloud-$n.las laz=$work/cloud-$n.laz
    [[ -f $las ]] || "$lodforge" -q generate points --points "$n" -o "$las"
    local files=("$las")
    if [[ -n ${LAZ_COMPRESS:-} ]]; then
      [[ -f $laz ]] || $LAZ_COMPRESS "$las" "$laz" > /dev/null
      files+=("$laz")
    fi
    local points
    points=$("$lodforge" info --header-only "$las" | awk '/^points / {print $2}' | tr -d ,)
    for input in "${files[@]}"; do
      declare -A runs=() rss=() size=()
      local tools=(lodforge potree)
      [[ -n ${OLD_LODFORGE:-} ]] && tools=(lodforge-old lodforge potree)
      for ((r = 0; r < ${POTREE_RUNS:-3}; ++r)); do
        for tool in "${tools[@]}"; do
          read -r seconds kib out < <(potree_once "$tool" "$input")
          runs[$tool]+="$seconds "
          rss[$tool]=$(( ${rss[$tool]:-0} > kib ? ${rss[$tool]:-0} : kib ))
          size[$tool]=$out
        done
      done
      for tool in "${tools[@]}"; do
        local median
        median=$(tr ' ' '\n' <<< "${runs[$tool]}" | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }')
        printf '| %-5s | %-4s | %-12s | %8ss | %7.2f M/s | %6d MiB | %7s | %s\n' "$n" "${input##*.}" "$tool" "$median" \
          "$(awk -v n="$points" -v s="$median" 'BEGIN { print n / s / 1e6 }')" $((rss[$tool] / 1024)) "${size[$tool]}" "${runs[$tool]}"
      done
      unset runs rss size
    done
  done
}
if [[ ${BENCH_ONLY:-} == potree ]]; then potree_section; exit 0; fi

# Surfaces beside PoissonRecon (issue 19): `POISSON=/path/to/PoissonRecon` (built from its public
# source outside the project; skipped without it). SURFACE_SIZES (default "1M") picks the clouds:
# `generate points` (normals, colours, 5 mm noise) and, as the ground truth, `generate scan` of
# twice as many triangles (the same terrain at the same detail). Both tools at a comparable
# resolution: PoissonRecon --depth 9 (512 cells over its bounding cube, 1.1× the cloud) and
# lodforge --voxel of the same size; each mesh measured against the truth by `lodforge compare`.
surface_section() {
  echo
  echo "== surfaces beside PoissonRecon (same cloud, one run each; $(nproc) threads)"
  missing_peer POISSON PoissonRecon && return
  printf '| %-5s | %-12s | %8s | %10s | %10s | %9s | %9s |\n' cloud tool wall "peak RSS" triangles hausdorff rms
  printf '|%s|%s|%s|%s|%s|%s|%s|\n' ------- -------------- ---------- ------------ ------------ ----------- -----------
  for n in ${SURFACE_SIZES:-1M}; do
    local cloud=$work/surface-$n.ply truth=$work/surface-truth-$n.ply
    [[ -f $cloud ]] || "$lodforge" -q generate points --points "$n" -o "$cloud"
    local count
    count=$("$lodforge" -q info "$cloud" --json 2> /dev/null | sed -n 's/^  "\(vertices\|points\)": \([0-9]*\).*/\2/p' | tail -1)
    [[ -f $truth ]] || "$lodforge" -q generate scan --triangles $((2 * count)) -o "$truth"
    local voxel
    voxel=$("$lodforge" info "$cloud" --json | awk '/"max"/ {m = 1} /"min"/ {m = 0} 
      /^ *-?[0-9.e+-]+,?$/ { v = $1 + 0; if (m) max[++a] = v; else min[++b] = v }
      END { s = 0; for (i = 1; i <= 3; ++i) if (max[i] - min[i] > s) s = max[i] - min[i]; print s * 1.1 / 512 }')
    # PoissonRecon closes the surface over its whole cube; users trim it by sampling density
    # (SurfaceTrimmer --trim 7 on a --density run, as its documentation shows): both rows.
    local trimmer=${POISSON_TRIMMER:-$(dirname "$POISSON")/SurfaceTrimmer}
    local tools=(lodforge poisson)
    [[ -x $trimmer ]] && tools+=(poisson+trim)
    for tool in "${tools[@]}"; do
      local out=$work/surface-$tool-$n.ply
      rm -f "$out"
      if [[ $tool == lodforge ]]; then
        read -r seconds kib < <(timed "$lodforge" -q reconstruct "$cloud" -o "$out" --voxel "$voxel")
      elif [[ $tool == poisson ]]; then
        read -r seconds kib < <(timed "$POISSON" --in "$cloud" --out "$out" --depth 9)
      else
        read -r s1 k1 < <(timed "$POISSON" --in "$cloud" --out "$out.dense.ply" --depth 9 --density)
        read -r s2 k2 < <(timed "$trimmer" --in "$out.dense.ply" --out "$out" --trim 7)
        seconds=$(awk -v a="$s1" -v b="$s2" 'BEGIN { print a + b }')
        kib=$(( k1 > k2 ? k1 : k2 ))
        rm -f "$out.dense.ply"
      fi
      local triangles
      triangles=$("$lodforge" info "$out" --json | sed -n 's/.*"triangles": \([0-9]*\).*/\1/p')
      "$lodforge" -q compare "$out" "$truth" --json "$work/surface-$tool.json"
      local h r
      h=$(sed -n 's/.*"hausdorff": \([0-9.e+-]*\).*/\1/p' "$work/surface-$tool.json")
      r=$(sed -n 's/.*"rms": \([0-9.e+-]*\).*/\1/p' "$work/surface-$tool.json")
      printf '| %-5s | %-12s | %7ss | %6d MiB | %10s | %9.3f | %9.4f |\n' "$n" "$tool" "$seconds" \
        $((kib / 1024)) "$triangles" "$h" "$r"
    done
    echo "(voxel $voxel for lodforge; ground truth: generate scan --triangles $((2 * count)))"
  done
}
if [[ ${BENCH_ONLY:-} == surface ]]; then surface_section; exit 0; fi

# A closed scan beside PoissonRecon (issue 37): 1 M points sampled from the horse scan (generate
# points --from, noise 0.05 % of its diagonal along the normals), both tools at PoissonRecon depth
# 9's cell (1.1 × the longest side / 512), each mesh measured against the horse, and where each
# one's largest distance lies (compare -v).
surface_closed_section() {
  echo
  echo "== a closed scan beside PoissonRecon (horse, 1 M samples; $(nproc) threads)"
  missing_peer POISSON PoissonRecon && return
  local data=${LODFORGE_DATA:-../shared/data}
  [[ -d $data ]] || data=/work/shared/data
  local mesh=$data/meshes/horse.ply cloud=$work/closed-1M.ply
  "$lodforge" -q generate points --from "$mesh" --points 1M --noise 0.0005 -o "$cloud"
  local voxel
  voxel=$("$lodforge" info "$mesh" --json | awk '/"max"/ {m = 1} /"min"/ {m = 0}
    /^ *-?[0-9.e+-]+,?$/ { v = $1 + 0; if (m) max[++a] = v; else min[++b] = v }
    END { s = 0; for (i = 1; i <= 3; ++i) if (max[i] - min[i] > s) s = max[i] - min[i]; print s * 1.1 / 512 }')
  printf '| %-9s | %8s | %10s | %10s | %11s | %11s | %-44s |\n' tool wall "peak RSS" triangles hausdorff rms "largest distance at"
  printf '|%s|%s|%s|%s|%s|%s|%s|\n' ----------- ---------- ------------ ------------ ------------- ------------- ----------------------------------------------
  for tool in lodforge poisson; do
    local out=$work/closed-$tool.ply
    rm -f "$out"
    if [[ $tool == lodforge ]]; then
      read -r seconds kib < <(timed "$lodforge" -q reconstruct "$cloud" -o "$out" --voxel "$voxel")
    else
      read -r seconds kib < <(timed "$POISSON" --in "$cloud" --out "$out" --depth 9)
    fi
    local triangles where
    triangles=$("$lodforge" info "$out" --json | sed -n 's/.*"triangles": \([0-9]*\).*/\1/p')
    # Where the larger of the two directions' largest distances lies (the Hausdorff distance's).
    local line ab ba
    line=$("$lodforge" -v compare "$out" "$mesh" --json "$work/closed-$tool.json" 2>&1 | grep '^largest ')
    ab=$(sed -n 's/^largest [^ ]* → [^ ]*: \([0-9.e+-]*\) at \(([^)]*)\);.*/\1 \2/p' <<< "$line")
    ba=$(sed -n 's/.*; [^ ]* → [^ ]*: \([0-9.e+-]*\) at \(([^)]*)\)$/\1 \2/p' <<< "$line")
    where=$(awk -v a="$ab" -v b="$ba" 'BEGIN { split(a, x, " "); split(b, y, " ");
      print (x[1] + 0 >= y[1] + 0 ? "mesh " x[2] x[3] x[4] : "scan " y[2] y[3] y[4]) }')
    local h r
    h=$(sed -n 's/.*"hausdorff": \([0-9.e+-]*\).*/\1/p' "$work/closed-$tool.json")
    r=$(sed -n 's/.*"rms": \([0-9.e+-]*\).*/\1/p' "$work/closed-$tool.json")
    printf '| %-9s | %7ss | %6d MiB | %10s | %11.4g | %11.4g | %-44s |\n' "$tool" "$seconds" \
      $((kib / 1024)) "$triangles" "$h" "$r" "$where"
    rm -f "$out"
  done
  echo "(voxel $voxel; distances in the horse's units)"
  rm -f "$cloud"
}
if [[ ${BENCH_ONLY:-} == surface-closed ]]; then surface_closed_section; exit 0; fi

# `tiles --surface` (the paper's Chunk path) on generated clouds (issue 19): points/s and peak
# RSS at 1 M and 10 M points (SURFACE_TILES_SIZES; add 100M for the large run), each at the
# default voxel (the points' own resolution: about 10 triangles a point) and at a fixed voxel of
# SURFACE_TILES_VOXEL metres (default 1: the mesh the same size for every cloud, so the figure is
# the pipeline's cost per point; SURFACE_TILES_DEFAULT=0 leaves the default voxel out). The
# table beside the paper's Table 2 is in docs/BENCHMARKS.md.
surface_tiles_section() {
  echo
  echo "== tiles --surface, the Chunk path ($(nproc) threads)"
  printf '| %-5s | %-8s | %9s | %11s | %9s | %12s | %7s |\n' points voxel wall "points/s" "peak RSS" triangles tiles
  printf '|%s|%s|%s|%s|%s|%s|%s|\n' ------- ---------- ----------- ------------- ----------- -------------- ---------
  for n in ${SURFACE_TILES_SIZES:-1M 10M}; do
    # SURFACE_TILES_FORMAT=las: LAS without normals (estimated, up), as airborne lidar comes.
    local cloud=$work/surface-$n.${SURFACE_TILES_FORMAT:-ply} out=$work/surface-tiles
    [[ -f $cloud ]] || "$lodforge" -q generate points --points "$n" -o "$cloud"
    local count
    count=$("$lodforge" -q info "$cloud" --json 2> /dev/null | sed -n 's/^  "\(vertices\|points\)": \([0-9]*\).*/\2/p' | tail -1)
    local voxels=("${SURFACE_TILES_VOXEL:-1}")
    [[ ${SURFACE_TILES_DEFAULT:-1} == 1 ]] && voxels=(default "${voxels[@]}")
    for voxel in "${voxels[@]}"; do
      local args=()
      [[ $voxel != default ]] && args=(--voxel "$voxel")
      rm -rf "$out"
      /usr/bin/time -v "$lodforge" tiles "$cloud" --surface -o "$out" "${args[@]}" > "$work/surface-tiles.log" 2> "$work/time.log" ||
        { tail -20 "$work/time.log"; exit 1; }
      local wall seconds kib triangles tiles
      wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$work/time.log")
      seconds=$(awk -F: '{ s = 0; for (i = 1; i <= NF; ++i) s = s * 60 + $i; print s }' <<< "$wall")
      kib=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$work/time.log")
      triangles=$(sed -n 's/^reconstructed \([0-9,]*\) triangles.*/\1/p' "$work/surface-tiles.log")
      tiles=$(sed -n 's/^wrote [^:]*: \([0-9,]*\) tiles.*/\1/p' "$work/surface-tiles.log")
      [[ $voxel == default ]] && voxel=$(sed -n 's/.*(voxel \([0-9.e+-]*\),.*/\1/p' "$work/surface-tiles.log")
      printf '| %-5s | %-8s | %8ss | %11s | %6d MiB | %12s | %7s |\n' "$n" "$voxel" "$seconds" \
        "$(awk -v n="$count" -v s="$seconds" 'BEGIN { printf "%.0f", n / s }')" $((kib / 1024)) "$triangles" "$tiles"
      rm -rf "$out"
    done
  done
}
if [[ ${BENCH_ONLY:-} == surface-tiles ]]; then surface_tiles_section; exit 0; fi

# CAD files through OpenCASCADE (issue 20): read and tessellate (`info`, which reads the whole
# file at the default deflection) for the real samples: ../shared/data/cad and Debian's
# occt-misc; wall time, peak RSS, parts (placed instances) and triangles per second.
cad_section() {
  echo
  echo "== CAD read + tessellate ($(nproc) threads, default --deflection 0.001 of each part)"
  printf '| %-16s | %8s | %8s | %9s | %6s | %9s | %10s | %9s | %12s |\n' file size wall "peak RSS" shapes instances triangles "parts/s" "triangles/s"
  printf '|%s|%s|%s|%s|%s|%s|%s|%s|%s|\n' ------------------ ---------- ---------- ----------- -------- ----------- ------------ ----------- --------------
  local samples=/usr/share/opencascade/data data=${LODFORGE_DATA:-../shared/data}
  [[ -d $data ]] || data=/work/shared/data
  for file in "$data/cad/as1_motor.step" "$samples/step/screw.step" "$samples/step/linkrods.step" \
              "$samples/iges/bearing.iges" "$samples/iges/hammer.iges" "$samples/occ/Ball.brep" \
              "$samples/occ/CrankArm.brep"; do
    local result seconds kib
    result=$(timed "$lodforge" -q info "$file" --json)
    seconds=${result% *} kib=${result#* }
    "$lodforge" -q info "$file" --json > "$work/cad-info.json"
    local shapes instances triangles
    shapes=$(sed -n 's/^    "shapes": \([0-9]*\).*/\1/p' "$work/cad-info.json")
    instances=$(sed -n 's/^    "instances": \([0-9]*\).*/\1/p' "$work/cad-info.json")
    triangles=$(sed -n 's/^  "triangles": \([0-9]*\).*/\1/p' "$work/cad-info.json")
    printf '| %-16s | %8s | %7ss | %6d MiB | %6s | %9s | %10s | %9s | %12s |\n' "$(basename "$file")" \
      "$(du -h "$file" | cut -f1)" "$seconds" $((kib / 1024)) "$shapes" "$instances" "$triangles" \
      "$(awk -v n="$instances" -v s="$seconds" 'BEGIN { printf "%.0f", n / s }')" \
      "$(awk -v n="$triangles" -v s="$seconds" 'BEGIN { printf "%.0f", n / s }')"
  done
  cad_generated_section
}

# Generated STEP assemblies (`generate cad -o X.step`) at CAD_STEP_PARTS parts (default 1000
# 10000): write, read + tessellate, and tiles end to end. 100000 works the same way but needs
# ~1.7 GB of disk, ~17 GiB and ~13 min to write, ~12.3 GiB and ~25 min to tile (BENCHMARKS.md).
cad_generated_section() {
  echo
  echo "== generated STEP assemblies ($(nproc) threads)"
  printf '| %-7s | %-15s | %9s | %10s | %8s | %10s | %9s | %12s |\n' parts step size wall "peak RSS" triangles "parts/s" "triangles/s"
  printf '|%s|%s|%s|%s|%s|%s|%s|%s|\n' --------- ----------------- ----------- ------------ ---------- ------------ ----------- --------------
  local parts
  for parts in ${CAD_STEP_PARTS:-1000 10000}; do
    local step=$work/cad$parts.step result seconds kib triangles
    result=$(timed "$lodforge" -q generate cad --objects "$parts" -o "$step")
    seconds=${result% *} kib=${result#* }
    printf '| %7s | %-15s | %9s | %9ss | %6d MiB | %10s | %9s | %12s |\n' "$parts" "write STEP" \
      "$(du -h "$step" | cut -f1)" "$seconds" $((kib / 1024)) "" \
      "$(awk -v n="$parts" -v s="$seconds" 'BEGIN { printf "%.0f", n / s }')" ""
    /usr/bin/time -v "$lodforge" -q info "$step" --json > "$work/cad-info.json" 2> "$work/time.log" ||
      { tail -20 "$work/time.log" >&2; exit 1; }
    result=$(seconds_and_kib "$work/time.log")
    seconds=${result% *} kib=${result#* }
    triangles=$(sed -n 's/^  "triangles": \([0-9]*\).*/\1/p' "$work/cad-info.json")
    printf '| %7s | %-15s | %9s | %9ss | %6d MiB | %10s | %9s | %12s |\n' "$parts" "read+tessellate" \
      "" "$seconds" $((kib / 1024)) "$triangles" \
      "$(awk -v n="$parts" -v s="$seconds" 'BEGIN { printf "%.0f", n / s }')" \
      "$(awk -v n="$triangles" -v s="$seconds" 'BEGIN { printf "%.0f", n / s }')"
    result=$(timed "$lodforge" -q tiles "$step" -o "$work/cad-tiles")
    seconds=${result% *} kib=${result#* }
    printf '| %7s | %-15s | %9s | %9ss | %6d MiB | %10s | %9s | %12s |\n' "$parts" "tiles" \
      "$(du -sh "$work/cad-tiles" | cut -f1)" "$seconds" $((kib / 1024)) "$triangles" \
      "$(awk -v n="$parts" -v s="$seconds" 'BEGIN { printf "%.0f", n / s }')" \
      "$(awk -v n="$triangles" -v s="$seconds" 'BEGIN { printf "%.0f", n / s }')"
    rm -rf "$step" "$work/cad-tiles"
  done
}
if [[ ${BENCH_ONLY:-} == cad ]]; then cad_section; exit 0; fi

# Repeated shapes: `build` with its shape cache and with --no-instances, then `extract` at half
# the vertices, on the real assemblies and a generated 10 K-part GLB (its bolts are shared).
instances_section() {
  echo
  echo "== build: repeated shapes simplified once, or every object on its own (--no-instances)"
  printf '| %-20s | %-9s | %8s | %9s | %8s | %8s | %14s | %11s |\n' input build wall "peak RSS" placed package "extract meshes" "extract GLB"
  printf '|%s|%s|%s|%s|%s|%s|%s|%s|\n' ---------------------- ----------- ---------- ----------- ---------- ---------- ---------------- -------------
  local data=${LODFORGE_DATA:-../shared/data}
  [[ -d $data ]] || data=/work/shared/data
  "$lodforge" -q generate cad --objects 10K -o "$work/cad10k.glb"
  for input in "$data/meshes/2CylinderEngine.glb" "$data/cad/as1_motor.step" "$work/cad10k.glb"; do
    for mode in instances own; do
      local flag=() log=$work/build.log result
      [[ $mode == own ]] && flag=(--no-instances)
      # One run: its message (how many were placed) to the log, its time and memory to time.log.
      /usr/bin/time -v "$lodforge" build "$input" -o "$work/inst.lfp" "${flag[@]}" > "$log" \
        2> "$work/time.log" || { tail -20 "$work/time.log" >&2; exit 1; }
      result=$(seconds_and_kib "$work/time.log")
      "$lodforge" -q extract "$work/inst.lfp" --ratio 0.5 -o "$work/inst.glb"
      printf '| %-20s | %-9s | %7ss | %5d MiB | %8s | %8s | %14s | %11s |\n' "$(basename "$input")" "$mode" \
        "${result% *}" $((${result#* } / 1024)) "$(sed -n 's/.*objects (\([0-9,]*\) placed.*/\1/p' "$log" | grep . || echo 0)" \
        "$(du -h "$work/inst.lfp" | cut -f1)" \
        "$(python3 -c 'import json,struct,sys; b=open(sys.argv[1],"rb").read(); n=struct.unpack("<I",b[12:16])[0]; print(len(json.loads(b[20:20+n])["meshes"]))' "$work/inst.glb")" \
        "$(du -h "$work/inst.glb" | cut -f1)"
    done
  done
  rm -f "$work/cad10k.glb" "$work/inst.lfp" "$work/inst.glb" "$work/build.log"
}
if [[ ${BENCH_ONLY:-} == instances ]]; then instances_section; exit 0; fi

# Textured scans (16 atlases of 4K, MeshLab's textured PLY) through tiles under a 512 MB limit:
# wall, peak RSS, input and output bytes, and each level's bytes against the level below.
textures_section() {
  echo
  echo "== tiles: textured scans, 16 x 4K atlases, --memory-limit 512M"
  printf '| %-10s | %8s | %9s | %9s | %9s | %-44s |
' triangles wall "peak RSS" input output "bytes per level (leaves first; % of the level below)"
  printf '|%s|%s|%s|%s|%s|%s|
' ------------ ---------- ----------- ----------- ----------- ----------------------------------------------
  local sizes=(2M)
  [[ ${BENCH_LARGE:-0} == 1 ]] && sizes+=(20M)
  for n in "${sizes[@]}"; do
    rm -rf "$work/tex" && mkdir -p "$work/tex"
    "$lodforge" -q generate scan --triangles "$n" --texture 4K --atlases 16 -o "$work/tex/scan.ply"
    local result levels
    result=$(timed "$lodforge" -q --memory-limit 512M tiles "$work/tex/scan.ply" -o "$work/tex/tiles")
    levels=$(for l in 0 1 2 3 4 5 6; do
      ls "$work"/tex/tiles/tiles/"$l"-*.glb > /dev/null 2>&1 || break
      du -cb "$work"/tex/tiles/tiles/"$l"-*.glb | tail -1 | cut -f1
    done | awk '{ if (NR > 1) printf " / %.1f MB (%d %%)", $1 / 1e6, 100 * $1 / prev; else printf "%.1f MB", $1 / 1e6; prev = $1 }')
    printf '| %-10s | %7ss | %5d MiB | %9s | %9s | %-44s |\n' "$n" "${result% *}" $((${result#* } / 1024)) \
      "$(du -sh --exclude=tiles "$work/tex" | cut -f1)" "$(du -sh "$work/tex/tiles" | cut -f1)" "$levels"
  done
  rm -rf "$work/tex"
}
# A textured OBJ streamed through tiles under a 512 MB limit (issue 36: "a 10 GB textured OBJ
# within --memory-limit"): a generated scan (16 atlases of 4K) converted to OBJ + MTL, then
# tiled. TEXTURED_OBJ_TRIANGLES sets the size (2M by default; 82M makes a 10 GB OBJ).
textured_obj_section() {
  echo
  echo "== tiles: a textured OBJ (16 x 4K atlases), --memory-limit 512M"
  printf '| %-10s | %9s | %8s | %9s | %9s |\n' triangles "OBJ size" wall "peak RSS" output
  printf '|%s|%s|%s|%s|%s|\n' ------------ ----------- ---------- ----------- -----------
  local n=${TEXTURED_OBJ_TRIANGLES:-2M}
  rm -rf "$work/texobj" && mkdir -p "$work/texobj"
  "$lodforge" -q generate scan --triangles "$n" --texture 4K --atlases 16 -o "$work/texobj/scan.ply"
  "$lodforge" -q convert "$work/texobj/scan.ply" -o "$work/texobj/obj/scan.obj"
  rm -f "$work/texobj/scan.ply"
  local result
  result=$(timed "$lodforge" -q --memory-limit 512M tiles "$work/texobj/obj/scan.obj" -o "$work/texobj/tiles")
  printf '| %-10s | %9s | %7ss | %5d MiB | %9s |\n' "$n" "$(du -h "$work/texobj/obj/scan.obj" | cut -f1)" \
    "${result% *}" $((${result#* } / 1024)) "$(du -sh "$work/texobj/tiles" | cut -f1)"
  rm -rf "$work/texobj"
}
if [[ ${BENCH_ONLY:-} == textured-obj ]]; then textured_obj_section; exit 0; fi

# Texture pages by format: the same textured scan tiled with PNG pages (lossless: the pages as
# baked, the source resampled) and with each lossy format; each page's PSNR against its PNG twin
# (`lodforge compare`), and the texture bytes per texel.
texture_formats_section() {
  echo
  echo "== tiles: texture pages by format (200 K-triangle scan, 4 atlases of 2K), PSNR against the lossless pages"
  printf '| %-12s | %7s | %12s | %13s | %13s | %9s |\n' format pages "image bytes" "bits / texel" "mean PSNR dB" "min PSNR"
  printf '|%s|%s|%s|%s|%s|%s|\n' -------------- --------- -------------- --------------- --------------- -----------
  rm -rf "$work/texfmt" && mkdir -p "$work/texfmt"
  "$lodforge" -q generate scan --triangles 200K --texture 2K --atlases 4 -o "$work/texfmt/scan.ply"
  local format quality texels=0
  for format in png jpeg:75 jpeg:85 jpeg:95 webp:85; do
    quality=${format#*:}
    [[ $quality == "$format" ]] && quality=85
    "$lodforge" -q tiles "$work/texfmt/scan.ply" -o "$work/texfmt/${format/:/-}" \
      --texture-format "${format%%:*}" --texture-quality "$quality"
    python3 scripts/glb-images.py "$work/texfmt/pages-${format/:/-}" "$work"/texfmt/"${format/:/-}"/tiles/*.glb > /dev/null
    if [[ $format == png ]]; then
      texels=$(python3 -c 'import struct,sys
total = 0
for path in sys.argv[1:]:
    with open(path, "rb") as f: f.read(16); w, h = struct.unpack(">II", f.read(8))
    total += w * h
print(total)' "$work"/texfmt/pages-png/*.png)
    fi
    local bytes report
    bytes=$(du -cb "$work"/texfmt/pages-"${format/:/-}"/* | tail -1 | cut -f1)
    report=-
    if [[ $format != png ]]; then
      "$lodforge" -q compare "$work/texfmt/pages-png" "$work/texfmt/pages-${format/:/-}" --json "$work/texfmt/psnr.json" > /dev/null
      report=$(python3 -c 'import json,sys
frames = json.load(open(sys.argv[1]))["frames"]
values = [f["psnr_db"] for f in frames if f["psnr_db"] is not None]
print(f"{sum(values) / len(values):.2f} {min(values):.2f}")' "$work/texfmt/psnr.json")
    fi
    printf '| %-12s | %7d | %12s | %13.2f | %13s | %9s |\n' "$format" \
      "$(ls "$work/texfmt/pages-${format/:/-}" | wc -l)" "$(numfmt --to=iec "$bytes")" \
      "$(awk -v b="$bytes" -v t="$texels" 'BEGIN { print 8 * b / t }')" \
      "$( [[ $report == - ]] && echo "lossless" || echo "${report% *}")" "$( [[ $report == - ]] && echo "-" || echo "${report#* }")"
  done
  rm -rf "$work/texfmt"
}
if [[ ${BENCH_ONLY:-} == textures ]]; then textures_section; texture_formats_section; exit 0; fi
if [[ ${BENCH_ONLY:-} == texture-formats ]]; then texture_formats_section; exit 0; fi

# Textured simplification beside gltfpack (issue 36): the same textured GLB (a generated scan, 16
# atlases of 4K) simplified to a tenth of its triangles by `lodforge convert --simplify 0.1` and
# by `gltfpack -si 0.1 -noq` (no quantization, so both keep full-precision positions and
# coordinates); wall and peak RSS of each, then `lodforge compare` of each result against the
# input: surface distance and the texture-space error in texels. GLTFPACK names the peer's
# binary (npm's gltfpack, installed outside the project).
gltfpack_section() {
  echo
  echo "== textured simplification beside gltfpack (2 M-triangle scan, 16 x 4K atlases, to a tenth)"
  missing_peer GLTFPACK gltfpack && return
  printf '| %-26s | %7s | %9s | %9s | %9s | %8s | %13s | %11s |\n' tool wall "peak RSS" triangles hausdorff rms "texels mean" "texels p95"
  printf '|%s|%s|%s|%s|%s|%s|%s|%s|\n' ---------------------------- --------- ----------- ----------- ----------- ---------- --------------- -------------
  rm -rf "$work/gp" && mkdir -p "$work/gp"
  "$lodforge" -q generate scan --triangles "${GLTFPACK_TRIANGLES:-2M}" --texture 4K --atlases 16 -o "$work/gp/scan.ply"
  "$lodforge" -q convert "$work/gp/scan.ply" -o "$work/gp/scan.glb"
  local tool result report
  for tool in "lodforge (1 thread)" "lodforge" "gltfpack"; do
    case $tool in
      "lodforge (1 thread)") result=$(timed "$lodforge" -q --threads 1 convert "$work/gp/scan.glb" -o "$work/gp/out.glb" --simplify 0.1) ;;
      lodforge) result=$(timed "$lodforge" -q convert "$work/gp/scan.glb" -o "$work/gp/out.glb" --simplify 0.1) ;;
      gltfpack) result=$(timed "$GLTFPACK" -i "$work/gp/scan.glb" -o "$work/gp/out.glb" -si 0.1 -noq) ;;
    esac
    "$lodforge" -q compare "$work/gp/scan.glb" "$work/gp/out.glb" --json "$work/gp/compare.json"
    report=$(python3 -c 'import json,sys
j = json.load(open(sys.argv[1])); t = j["texture_texels"]
print("%.4g %.4g %.3g %.3g" % (j["hausdorff"], j["rms"], t["mean"], t["p95"]))' "$work/gp/compare.json")
    read -r h r tm tp <<< "$report"
    printf '| %-26s | %6ss | %5d MiB | %9s | %9s | %8s | %13s | %11s |\n' "$tool" "${result% *}" $((${result#* } / 1024)) \
      "$("$lodforge" info "$work/gp/out.glb" | sed -n 's/^triangles *//p')" "$h" "$r" "$tm" "$tp"
  done
  rm -rf "$work/gp"
}
if [[ ${BENCH_ONLY:-} == gltfpack ]]; then gltfpack_section; exit 0; fi

# Declared against measured geometric error of mesh tilesets (issue 38): every tile with
# children against the union of the leaves under it, by dense sampling (bench_tile_error).
tile_error_section() {
  echo
  echo "== tile geometric error: measured (symmetric Hausdorff to the leaves below) / declared"
  local data=${LODFORGE_DATA:-../shared/data}
  [[ -d $data ]] || data=/work/shared/data
  for mesh in horse.ply stanford-bunny.obj; do
    "$lodforge" -q tiles "$data/meshes/$mesh" -o "$work/te-${mesh%%.*}"
  done
  "$lodforge" -q generate cad --objects 2K -o "$work/te-cad.ply"
  "$lodforge" -q tiles "$work/te-cad.ply" -o "$work/te-cad2k"
  for n in 1M 10M; do
    "$lodforge" -q generate scan --triangles "$n" -o "$work/te-scan.ply"
    "$lodforge" -q tiles "$work/te-scan.ply" -o "$work/te-scan$n"
  done
  build/release/bench/bench_tile_error "$work/te-cad2k" "$work/te-scan10M"
  # Point tiles: a dropped point's distance to the nearest shown one.
  "$lodforge" -q tiles "$data/points/autzen_trim.laz" -o "$work/te-autzen"
  "$lodforge" -q generate points --points 1M -o "$work/te-points.ply"
  "$lodforge" -q tiles "$work/te-points.ply" -o "$work/te-points1M"
  build/release/bench/bench_tile_error "$work/te-autzen" "$work/te-points1M"
  # With certified brackets (branch and bound; the assembly's flat faces take minutes, left out)
  # and the bound chained per triangle.
  build/release/bench/bench_tile_error --certify --chain 0.1 "$work/te-horse" \
    "$work/te-stanford-bunny" "$work/te-scan1M"
  rm -rf "$work"/te-*
}
if [[ ${BENCH_ONLY:-} == tile-error ]]; then tile_error_section; exit 0; fi

# Explicit against implicit tiling (issue 38): the same scan tiled both ways, tileset.json size
# and CesiumJS's time to its first frame (bench/cesium_first_frame.mjs, headless chromium).
implicit_section() {
  echo
  local n=${IMPLICIT_TRIANGLES:-10M}
  echo "== explicit against implicit tiling: a $n-triangle scan in CesiumJS"
  "$lodforge" -q generate scan --triangles "$n" -o "$work/im-scan.ply"
  for mode in off on; do
    read -r s kib < <(timed "$lodforge" -q tiles "$work/im-scan.ply" -o "$work/im-$mode" \
      --implicit-tiling "$mode" --origin 8.54,47.37,400)
    echo "tiles --implicit-tiling $mode: $s s, $((kib / 1024)) MiB peak, $(du -sh "$work/im-$mode" | cut -f1)," \
      "tileset.json $(stat -c %s "$work/im-$mode/tileset.json") bytes"
  done
  node bench/cesium_first_frame.mjs --runs "${IMPLICIT_RUNS:-3}" "$work/im-off" "$work/im-on"
  rm -rf "$work"/im-*
}
if [[ ${BENCH_ONLY:-} == implicit ]]; then implicit_section; exit 0; fi

# A billion triangles end to end (issue 37; about 80 GB of disk at its peak): generation, then
# tiles with the work directory's size, the process's bytes read and written, its memory and
# the stage it is in polled every 5 s into build/bench/billion-poll.log.
billion_section() {
  echo
  echo "== a billion-triangle scan end to end"
  read -r s kib < <(timed "$lodforge" generate scan --triangles 1G -o "$work/scan1g.ply")
  echo "generate scan --triangles 1G: $s s, $((kib / 1024)) MiB peak"
  /usr/bin/time -v "$lodforge" -v tiles "$work/scan1g.ply" -o "$work/tiles1g" 2> "$work/billion.log" &
  local timer=$! pid=""
  while kill -0 $timer 2> /dev/null; do
    [[ -n $pid ]] || pid=$(pgrep -P $timer || true)
    if [[ -n $pid && -r /proc/$pid/io ]]; then
      echo "$(date +%s) $(awk '/^(read|write)_bytes/ {printf "%s=%s ", $1, $2}' /proc/$pid/io)" \
        "rss=$(awk '/VmRSS/ {print $2}' /proc/$pid/status) work=$(du -sb "$work/tiles1g.work" | cut -f1)" \
        "| $(tr '\r' '\n' < "$work/billion.log" | grep '^tiles' | tail -1)" >> "$work/billion-poll.log"
    fi
    sleep 5
  done
  wait $timer
  read -r s kib < <(seconds_and_kib "$work/billion.log")
  echo "tiles: $s s, $((kib / 1024)) MiB peak, $(du -sh "$work/tiles1g" | cut -f1) written"
  rm -rf "$work/scan1g.ply" "$work/tiles1g"
}
if [[ ${BENCH_ONLY:-} == billion ]]; then billion_section; exit 0; fi

# Ranks against threads (issue 39): the same input tiled (or reconstructed) by one process with
# 2 threads and by an OpenMPI job of 2 ranks with 1 thread each (each rank bound to its core,
# mpirun's default), alternately; wall time, each rank's peak memory (a /usr/bin/time per rank),
# outputs compared. A scan (DISTRIBUTED_TRIANGLES), an airborne LAS (DISTRIBUTED_POINTS) and a
# cloud's surface (`reconstruct`, DISTRIBUTED_SURFACE_POINTS), and the LAS as LAZ when
# LAZ_COMPRESS is set; DISTRIBUTED_ONLY=scan, points, laz or surface runs one. DISTRIBUTED_MPIRUN_ARGS goes to mpirun ("--mca pml ob1": OpenMPI's
# shared-memory transport without UCX's start-up, docs/distributed.md).
ranks_against_threads() {  # the input, the subcommand, the output's suffix; the table, -v lines
  local input=$1 command=$2 suffix=$3 runs=${DISTRIBUTED_RUNS:-3} extra
  read -ra extra <<< "${DISTRIBUTED_MPIRUN_ARGS:-}"
  local mpi=(mpirun --allow-run-as-root -np 2 "${extra[@]}") one_out="$work/dist-one$suffix" ranks_out="$work/dist-ranks$suffix"
  printf '| run | 1 process x 2 threads | peak RSS | 2 ranks x 1 thread | peak RSS rank 0 / 1 | ranks / threads |\n|---|---:|---:|---:|---:|---:|\n'
  for run in $(seq "$runs"); do
    # Each run starts with the page cache's dirty pages written out (sync): a 1 GB tileset
    # still being flushed slows whichever run comes next.
    rm -rf "$one_out" "$ranks_out"
    sync
    read -r one kib < <(timed "$lodforge" -q --threads 2 "$command" "$input" -o "$one_out")
    sync
    # Each rank under its own /usr/bin/time, the job's wall time from one around mpirun.
    /usr/bin/time -f "%e" -o "$work/dist-time" "${mpi[@]}" \
      sh -c '/usr/bin/time -f "%M" -o "$0-$OMPI_COMM_WORLD_RANK" "$@"' "$work/dist-rank" \
      "$lodforge" -q --threads 1 "$command" "$input" -o "$ranks_out"
    local ranks
    ranks=$(cat "$work/dist-time")
    diff -rq "$one_out" "$ranks_out" > /dev/null || { echo "the two outputs differ" >&2; exit 1; }
    printf '| %d | %.2f s | %d MiB | %.2f s | %d / %d MiB | %.3f |\n' "$run" "$one" $((kib / 1024)) "$ranks" \
      $(($(cat "$work/dist-rank-0") / 1024)) $(($(cat "$work/dist-rank-1") / 1024)) "$(echo "$ranks / $one" | bc -l)"
  done
  rm -rf "$ranks_out"
  "${mpi[@]}" "$lodforge" -v --threads 1 "$command" "$input" -o "$ranks_out" 2>&1 |
    grep -E "^(rank|2 ranks|streamed)"
  rm -rf "$one_out" "$ranks_out" "$work"/dist-rank-* "$work/dist-time"
}
distributed_input() {  # kind (scan, points or surface), what it is, its file, the subcommand,
  # the output's suffix, then `generate` arguments
  local kind=$1 label=$2 file=$3 command=$4 suffix=$5
  shift 5
  [[ ${DISTRIBUTED_ONLY:-$kind} == "$kind" ]] || return 0
  echo
  echo "== ranks against threads: $command $label, 1 process x 2 threads and 2 ranks x 1 thread"
  if [[ $file == *.laz ]]; then  # lodforge writes no LAZ: LAZ_COMPRESS makes it from a LAS
    "$lodforge" -q generate "$@" -o "${file%.laz}.las"
    "$LAZ_COMPRESS" "${file%.laz}.las" "$file" > /dev/null
    rm -f "${file%.laz}.las"
  else
    "$lodforge" -q generate "$@" -o "$file"
  fi
  ranks_against_threads "$file" "$command" "$suffix"
  rm -f "$file"
}
distributed_section() {
  local n=${DISTRIBUTED_TRIANGLES:-10M} points=${DISTRIBUTED_POINTS:-20M}
  local surface=${DISTRIBUTED_SURFACE_POINTS:-2M}
  distributed_input scan "a $n-triangle scan" "$work/dist-scan.ply" tiles "" scan --triangles "$n"
  distributed_input points "a $points-point LAS" "$work/dist-points.las" tiles "" points --points "$points"
  # The same points as LAZ when LAZ_COMPRESS names a compressor (the potree section's).
  [[ -z ${LAZ_COMPRESS:-} ]] ||
    distributed_input laz "a $points-point LAZ" "$work/dist-points.laz" tiles "" points --points "$points"
  distributed_input surface "a $surface-point LAS (no normals)" "$work/dist-surface.las" reconstruct .ply \
    points --points "$surface"
}
if [[ ${BENCH_ONLY:-} == distributed ]]; then distributed_section; exit 0; fi

if [[ -n ${skip_generators:-} ]]; then simplify_section; exit 0; fi

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
simplify_section
tiles_section
points_section
serve_section
laz_section
potree_section
surface_section
surface_closed_section
surface_tiles_section
cad_section
instances_section
textures_section
textured_obj_section
texture_formats_section
gltfpack_section
tile_error_section
render_section
runtime_section
