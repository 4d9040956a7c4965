#!/usr/bin/env bash
# `lodforge reconstruct` and `tiles --surface` across the ranks of an OpenMPI job
# (docs/distributed.md), run by OpenMPI's own mpirun on this one machine (--oversubscribe): rank 0
# sorts the points into runs, every rank makes its share of the runs, rank 0 joins them. The mesh
# is byte for byte the one process's with 1 to 3 ranks, also with the normals estimated by the
# ranks and with more ranks than runs; a rank killed mid-share stops the job naming what it did,
# and --resume finishes without remaking the runs that were done (`reconstruct` and `tiles
# --surface`); a job on an output a run is writing is refused.
set -euo pipefail
lodforge=$1 out=$2 sanitized=${3:-0}
source "$(dirname "$0")/mpi_common.sh"
rm -rf "$out" && mkdir -p "$out"
cd "$out"

# 100 K points in 17 runs of chunks (--memory-limit 64M holds about 6 K points a run); 60 K in
# 8 runs for a surface's tiles; 30 K in 12 chunks for what one run holds.
"$lodforge" -q generate points --points 100K -o cloud.ply
"$lodforge" -q generate points --points 60K -o mid.ply
"$lodforge" -q generate points --points 30K -o small.ply
limit=(--memory-limit 64M)
"$lodforge" -v "${limit[@]}" reconstruct cloud.ply -o one.ply > one.err 2>&1
grep -q "35 chunks in 17 runs" one.err || fail "not 17 runs of chunks: $(cat one.err)"
for ranks in $(rank_counts 1 2 3); do
  "${mpi[@]}" -np $ranks "$lodforge" -v "${limit[@]}" reconstruct cloud.ply -o np$ranks.ply \
    2> np$ranks.err
  same np$ranks.ply one.ply "reconstruct, $ranks ranks"
done
# Each rank made a share (chunks made a rank from -v), and the work went when the job was done.
grep -qE "^3 ranks: the points sorted into runs by rank 0 .*; the runs made by the ranks, [1-9][0-9]* to [0-9]+ chunks a rank" np3.err ||
  fail "the runs were not shared by 3 ranks: $(cat np3.err)"
[[ ! -e np3.ply.work ]] || fail "the job left its work directory"

# A LAS has no normals: the ranks estimate them run by run (7 runs), rank 0 merges them.
"$lodforge" -q generate points --points 40K -o cloud.las
"$lodforge" -q "${limit[@]}" reconstruct cloud.las -o las-1.ply
"${mpi[@]}" -np 2 "$lodforge" -v "${limit[@]}" reconstruct cloud.las -o las-np2.ply > las.err 2>&1
same las-np2.ply las-1.ply "normals estimated by the ranks, 2 ranks"
grep -q "normals estimated" las.err || fail "the LAS's normals were not estimated: $(cat las.err)"

# More ranks than runs: the default budget holds the cloud in one run; 3 ranks, two idle.
"$lodforge" -q reconstruct small.ply -o whole.ply
"${mpi[@]}" -np 3 "$lodforge" -v reconstruct small.ply -o whole-np3.ply 2> whole.err
same whole-np3.ply whole.ply "more ranks than runs"
grep -q "the runs made by the ranks, 0 to 12 chunks a rank" whole.err ||
  fail "one rank did not make the one run: $(cat whole.err)"

# A rank killed (SIGKILL) after its second run: the job stops naming it and its step; the
# finished runs stay, and --resume (by 2 ranks) takes them and writes the same mesh.
set +e
"${mpi_killed[@]}" -np 1 "$lodforge" "${limit[@]}" reconstruct cloud.ply -o killed.ply : \
  -np 1 -x LODFORGE_INTERRUPT_AFTER=run:2:kill "$lodforge" "${limit[@]}" reconstruct cloud.ply \
  -o killed.ply > killed.out 2> killed.err
code=$?
set -e
[[ $code -ne 0 ]] || fail "a job with a killed rank exited 0"
grep -qE "^  rank 1 of 2 \(.*\): making runs of chunks, 17 in all" killed.err ||
  fail "the stop does not say what rank 1 was doing: $(cat killed.err)"
[[ ! -e killed.ply ]] || fail "the killed job wrote its output"
kept=$(find killed.ply.work -name 'run-*.pieces' | wc -l)
[[ $kept -ge 2 ]] || fail "only $kept runs kept after the kill"
"${mpi[@]}" -np 2 "$lodforge" -v "${limit[@]}" reconstruct cloud.ply -o killed.ply --resume \
  > resumed.err 2>&1
resumed=$(sed -nE 's/.* in 17 runs, ([0-9]+) resumed.*/\1/p' resumed.err)
[[ -n $resumed && $resumed -ge 2 && $resumed -eq $kept ]] ||
  fail "--resume took ${resumed:-no} runs of the $kept kept: $(cat resumed.err)"
same killed.ply one.ply "killed rank, then --resume"

# A surface's tiles: the ranks make the reconstruction's runs, then build the octree.
"$lodforge" -q "${limit[@]}" tiles mid.ply --surface -o surface-1 --chunk-size 100
"${mpi[@]}" -np 3 "$lodforge" -v "${limit[@]}" tiles mid.ply --surface -o surface-np3 \
  --chunk-size 100 2> surface.err
same surface-np3 surface-1 "tiles --surface, 3 ranks"
grep -q "3 ranks: the surface's runs made by the ranks, " surface.err ||
  fail "the surface was not made by the ranks: $(cat surface.err)"
# Its reconstruction stopped by a killed rank resumes too: the kept runs taken, the same tileset.
set +e
"${mpi_killed[@]}" -np 1 "$lodforge" "${limit[@]}" tiles mid.ply --surface -o surface-killed \
  --chunk-size 100 : -np 1 -x LODFORGE_INTERRUPT_AFTER=run:2:kill "$lodforge" "${limit[@]}" \
  tiles mid.ply --surface -o surface-killed --chunk-size 100 > surface-killed.out 2>&1
code=$?
set -e
[[ $code -ne 0 ]] || fail "a surface job with a killed rank exited 0"
"${mpi[@]}" -np 2 "$lodforge" "${limit[@]}" tiles mid.ply --surface -o surface-killed \
  --chunk-size 100 --resume > surface-resumed.out 2>&1
grep -qE "runs, [1-9][0-9]* resumed" surface-resumed.out ||
  fail "the surface's kept runs were not taken: $(cat surface-resumed.out)"
same surface-killed surface-np3 "tiles --surface: killed rank, then --resume"

# A job on an output that a one-process run is writing is refused (exit 2), naming that run,
# which finishes (held stopped by SIGSTOP while the job tries).
"$lodforge" -q --threads 1 reconstruct small.ply -o busy.ply &
first=$!
hold $first busy.ply.work/.lodforge-lock
set +e
"${mpi[@]}" -np 2 "$lodforge" -q reconstruct small.ply -o busy.ply 2> busy.err
code=$?
set -e
release $first
wait $first || fail "the first run failed"
[[ $code -eq 2 ]] && grep -q "another lodforge run (pid $first on" busy.err ||
  fail "a job on a busy output: exit $code, $(cat busy.err)"
same busy.ply whole.ply "the first run, beside the refused job"

finish "distributed reconstruction"
