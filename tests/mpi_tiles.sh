#!/usr/bin/env bash
# `lodforge tiles` across the ranks of an OpenMPI job (docs/distributed.md), run by OpenMPI's own
# mpirun on this one machine (--oversubscribe: more ranks than cores): a scan by 2 to 4 ranks
# (and mpirun -np 1, a job of one), a PLY with a quad, a textured scan, a 300-part assembly and
# point clouds (LAS with extra bytes, PLY, one node or two) are byte for byte the tileset one
# process writes (a reconstructed surface: mpi_reconstruct.sh); more ranks than chunks; a rank
# killed mid-octree or mid-ranking stops the job with a message naming it and what it was doing,
# and --resume finishes a mesh without rebuilding what was done; a second run on an output being
# written is refused, a mesh's or a point cloud's.
set -euo pipefail
lodforge=$1 out=$2 sanitized=${3:-0} data=${4:-}
[[ -d $data/points ]] || { echo "usage: mpi_tiles.sh LODFORGE OUT SANITIZED DATA (the shared data folder)" >&2; exit 1; }
data=$(cd "$data" && pwd)
source "$(dirname "$0")/mpi_common.sh"
rm -rf "$out" && mkdir -p "$out"
cd "$out"

# In the sanitizer tree, 100 K triangles over the same ground: the same chunks and rounds (chunks
# are cut by --chunk-size, in metres), a third of the work for every run that tiles it.
"$lodforge" -q generate scan --triangles "$([[ $sanitized == 1 ]] && echo 100K || echo 300K)" -o scan.ply
"$lodforge" -q tiles scan.ply -o scan-1 --chunk-size 60
# 1, 2 and 4 ranks (not in the sanitizer tree: mpi_common.sh), and 3 below, with -v.
[[ $sanitized == 1 ]] || for ranks in 1 2 4; do
  "${mpi[@]}" -np $ranks "$lodforge" -q tiles scan.ply -o scan-np$ranks --chunk-size 60
  same scan-np$ranks scan-1 "scan, $ranks ranks"
done
# The work was shared: -v says how (the scan read in slices by every rank). No transport given
# here (the other jobs ask for the shared-memory one, mpi_common.sh).
"${mpi_default[@]}" -np 3 "$lodforge" -v tiles scan.ply -o scan-np3 --chunk-size 60 2> scan-v.err
same scan-np3 scan-1 "scan, 3 ranks"
grep -q "3 ranks: the input read in slices by every rank; subtrees under level" scan-v.err ||
  fail "no share in -v: $(cat scan-v.err)"

# A quad among the triangles: faces cannot be found by index, so rank 0 chunks the file alone
# (perl, which every Debian has, writes it).
perl -e '
  my $n = 60; my $i = 0; my (@v, @f);
  for my $y (0..$n) { for my $x (0..$n) { push @v, pack("f<6", $x, $y, sin($x/5)*cos($y/7)*3, 0, 0, 1) } }
  for my $y (0..$n-1) { for my $x (0..$n-1) {
    my ($a, $b, $c, $d) = ($y*($n+1)+$x, $y*($n+1)+$x+1, ($y+1)*($n+1)+$x+1, ($y+1)*($n+1)+$x);
    if ($i++ == 1800) { push @f, pack("C l<4", 4, $a, $b, $c, $d) }
    else { push @f, pack("C l<3", 3, $a, $b, $c), pack("C l<3", 3, $a, $c, $d) } } }
  print "ply\nformat binary_little_endian 1.0\nelement vertex ", scalar(@v), "\n",
    (map { "property float $_\n" } qw(x y z nx ny nz)), "element face ", scalar(@f),
    "\nproperty list uchar int vertex_indices\nend_header\n", @v, @f;' > quad.ply
"$lodforge" -q tiles quad.ply -o quad-1 --chunk-size 8
"${mpi[@]}" -np 3 "$lodforge" -v tiles quad.ply -o quad-np3 --chunk-size 8 2> quad.err
same quad-np3 quad-1 "faces of two sizes, 3 ranks"
grep -q "3 ranks: the input chunked by rank 0" quad.err || fail "the quad file was not chunked by rank 0: $(cat quad.err)"

# A textured scan (rank 0 chunks it and makes the texture pyramids; the others take them).
"$lodforge" -q generate scan --triangles 50K --texture 512 -o textured.ply
"$lodforge" -q tiles textured.ply -o textured-1 --chunk-size 120
"${mpi[@]}" -np 3 "$lodforge" -q tiles textured.ply -o textured-np3 --chunk-size 120
same textured-np3 textured-1 "textured scan, 3 ranks"

# An uneven input: a coarse sheet with a patch 25 times denser in one corner (two surfaces, as
# perl writes them). Each rank's share of the leaf triangles is within 20 % of the busiest's.
perl -e '
  my (@v, @f);
  sub sheet { my ($n, $size, $z) = @_; my $base = @v;
    for my $y (0..$n) { for my $x (0..$n) {
      push @v, pack("f<6", $x * $size / $n, $y * $size / $n, $z + sin($x * $size / $n / 3), 0, 0, 1) } }
    for my $y (0..$n-1) { for my $x (0..$n-1) {
      my ($a, $b, $c, $d) = map { $base + $_ } ($y*($n+1)+$x, $y*($n+1)+$x+1, ($y+1)*($n+1)+$x+1, ($y+1)*($n+1)+$x);
      push @f, pack("C l<3", 3, $a, $b, $c), pack("C l<3", 3, $a, $c, $d) } } }
  sheet(120, 100, 0); sheet(120, 20, 5);
  print "ply\nformat binary_little_endian 1.0\nelement vertex ", scalar(@v), "\n",
    (map { "property float $_\n" } qw(x y z nx ny nz)), "element face ", scalar(@f),
    "\nproperty list uchar int vertex_indices\nend_header\n", @v, @f;' > uneven.ply
"$lodforge" -q tiles uneven.ply -o uneven-1 --chunk-size 6
for ranks in $(rank_counts 2 3); do
  "${mpi[@]}" -np $ranks "$lodforge" -v tiles uneven.ply -o uneven-np$ranks --chunk-size 6 2> uneven.err
  same uneven-np$ranks uneven-1 "uneven input, $ranks ranks"
  read -r least most < <(sed -nE 's/.*subtrees under level [0-9]+, ([0-9,]+) to ([0-9,]+) leaf triangles a rank.*/\1 \2/p' uneven.err | tr -d ,) || true
  [[ -n $most ]] && awk -v l="$least" -v m="$most" 'BEGIN { exit !(l >= 0.8 * m) }' ||
    fail "uneven input, $ranks ranks: ${least:-?} to ${most:-?} leaf triangles a rank: $(cat uneven.err)"
done

"$lodforge" -q generate cad --objects 300 --seed 3 -o cad.glb
"$lodforge" -q tiles cad.glb -o cad-1
"${mpi[@]}" -np 3 "$lodforge" -q tiles cad.glb -o cad-np3
same cad-np3 cad-1 "assembly (parts.json), 3 ranks"

"$lodforge" -q generate points --points 20K -o points.ply

# Point clouds: every rank reads a slice of the input; the ranks split the nodes too big for
# memory level by level, then each splits and ranks its share of the rest and writes its share
# of the tiles. A LAS
# with extra bytes (their own work file, reordered with the points) and a PLY, each one node in
# memory (the other ranks read and write tiles); a LAS of 16 nodes shared by 2 and 3 ranks.
"$lodforge" -q generate points --points 120K --extra-bytes -o cloud.las
"$lodforge" -q tiles cloud.las -o cloud-1 --block-size 8000
for ranks in $(rank_counts 1 2 3 4); do
  "${mpi[@]}" -np $ranks "$lodforge" -q tiles cloud.las -o cloud-np$ranks --block-size 8000
  same cloud-np$ranks cloud-1 "point cloud (LAS, extra bytes), $ranks ranks"
done
"$lodforge" -q tiles points.ply -o points-1 --block-size 3000
"${mpi[@]}" -np 3 "$lodforge" -q tiles points.ply -o points-np3 --block-size 3000
same points-np3 points-1 "point cloud (PLY with normals), 3 ranks"
# Several nodes: the partition holds 4 MB of points at once (LODFORGE_PARTITION_BYTES, the
# tests' knob), about 48 K points of this LAS (84 bytes each in memory): 16 nodes of 25 K.
export LODFORGE_PARTITION_BYTES=4000000
"$lodforge" -q generate points --points 400K --extra-bytes -o large.las
"$lodforge" -q tiles large.las -o large-1 --block-size 10000
for ranks in $(rank_counts 2 3); do
  "${mpi[@]}" -np $ranks "$lodforge" -v tiles large.las -o large-np$ranks --block-size 10000 \
    2> large.err
  same large-np$ranks large-1 "point cloud of 16 nodes, $ranks ranks"
done
grep -q "3 ranks: the input read in slices by every rank (done at" large.err ||
  fail "the LAS was not read in slices: $(cat large.err)"
# Each rank's share of the points within 20 % of the busiest's (whole nodes, largest first).
shares=$(grep -oE "rank [0-9] split and ranked [0-9,]+ points" large.err |
  sed -E 's/.* ranked ([0-9,]+) points/\1/' | tr -d , | tr '\n' ' ')
awk -v s="$shares" 'BEGIN { n = split(s, a, " "); if (n != 3) exit 1; lo = a[1]; hi = a[1]; t = 0
  for (i = 1; i <= n; ++i) { t += a[i]; if (a[i] < lo) lo = a[i]; if (a[i] > hi) hi = a[i] }
  exit !(t == 400000 && lo >= 0.8 * hi) }' ||
  fail "the partition was not shared among the ranks: $(cat large.err)"
# A LAZ file is read in slices too, each rank decoding from the chunk that holds its first point
# (autzen_trim.laz: chunks of 50,000, 50,000 and 10,000 points; slices of 65,536).
"$lodforge" -q tiles "$data/points/autzen_trim.laz" -o laz-1 --block-size 5000
"${mpi[@]}" -np 2 "$lodforge" -v tiles "$data/points/autzen_trim.laz" -o laz-np2 --block-size 5000 \
  2> laz.err
same laz-np2 laz-1 "LAZ, read in slices, 2 ranks"
grep -q "2 ranks: the input read in slices by every rank (done at" laz.err ||
  fail "the LAZ was not read in slices: $(cat laz.err)"
# A text cloud has no records at known places: rank 0 reads it alone, the rest is shared.
awk 'BEGIN { for (i = 0; i < 4000; ++i) printf "%.3f %.3f %.3f\n", i % 80, int(i / 80), sin(i / 50) }' > text.xyz
"$lodforge" -q tiles text.xyz -o text-1 --block-size 500
"${mpi[@]}" -np 2 "$lodforge" -v tiles text.xyz -o text-np2 --block-size 500 2> text.err
same text-np2 text-1 "text cloud, read by rank 0, 2 ranks"
grep -q "2 ranks: the input read by rank 0 (done at" text.err ||
  fail "the text cloud was not read by rank 0: $(cat text.err)"
# A rank killed with its second node of the partition staged in its scratch files, not yet in
# place: the job stops, rank 0 says what rank 1 was doing, and the work stays; --resume by 3 ranks
# takes the split input and every node done or staged (rank 0 puts rank 1's in place), and
# writes the same tileset.
set +e
"${mpi_killed[@]}" -np 1 "$lodforge" tiles large.las -o large-killed --block-size 10000 : \
  -np 1 -x LODFORGE_INTERRUPT_AFTER=pointstaged:2:kill "$lodforge" tiles large.las -o large-killed \
  --block-size 10000 > large-killed.out 2> large-killed.err
code=$?
set -e
[[ $code -ne 0 ]] || fail "a point job with a killed rank exited 0"
grep -qE "^  rank 1 of 2 \(.*\): splitting and ranking [0-9]+ of the partition's [0-9]+ nodes" \
  large-killed.err || fail "the stop does not say what rank 1 was doing: $(cat large-killed.err)"
grep -q "the finished work is kept in large-killed.work" large-killed.err ||
  fail "the killed point job does not say its work is kept: $(cat large-killed.err)"
[[ ! -e large-killed ]] || fail "the killed point job left a tileset"
done_before=$(find large-killed.work/points/nodes -name '*.json' | wc -l)  # done or staged
[[ -n $(find large-killed.work/points/nodes -name '*.staged.json') ]] ||
  fail "rank 1 left no node staged: $(ls large-killed.work/points/nodes)"
"${mpi[@]}" -np 3 "$lodforge" -v tiles large.las -o large-killed --block-size 10000 --resume \
  2> large-resumed.err
taken=$(sed -nE "s/.*resumed: the input as the interrupted run split it, ([0-9]+) of the partition's 16 nodes.*/\1/p" \
  large-resumed.err)
[[ -n $taken && $taken -ge $done_before && $done_before -ge 2 ]] ||
  fail "--resume took ${taken:-no} nodes of the $done_before ranked: $(cat large-resumed.err)"
same large-killed large-1 "point job: killed rank, then --resume by 3 ranks"
[[ ! -e large-killed.work ]] || fail "the resumed point job left its work behind"
unset LODFORGE_PARTITION_BYTES

# More ranks than chunks: a small scan in two chunks, 4 ranks (the split is their parent, the
# root: three ranks have nothing to build).
"$lodforge" -q generate scan --triangles 20K -o small.ply
"$lodforge" -q tiles small.ply -o small-1 --chunk-size 400
"${mpi[@]}" -np 4 "$lodforge" -q tiles small.ply -o small-np4 --chunk-size 400
same small-np4 small-1 "more ranks than chunks"

# A rank killed (SIGKILL) after its third node: the job stops, naming the rank; the work stays.
set +e
"${mpi_killed[@]}" -np 1 "$lodforge" tiles scan.ply -o killed --chunk-size 60 : \
  -np 1 -x LODFORGE_INTERRUPT_AFTER=node:3:kill "$lodforge" tiles scan.ply -o killed --chunk-size 60 \
  > killed.out 2> killed.err
code=$?
set -e
[[ $code -ne 0 ]] || fail "a job with a killed rank exited 0"
grep -q "^  rank 1 of 2 (" killed.err || fail "rank 0 does not say what rank 1 did: $(cat killed.err)"
grep -qE "building its [0-9]+ nodes of round 1 of [0-9]+ of the octree; [0-9]+ nodes done" killed.err ||
  fail "the stop does not say what rank 1 was doing: $(cat killed.err)"
[[ -d killed.work ]] || fail "the work directory is gone after the kill"
done_before=$(find killed.work/nodes -name '*.json' | wc -l)
# What a rank killed while writing a tile leaves: --resume must not ship it in the tileset.
echo partial > killed.work/tileset/tiles/planted.glb.tmp-4242-7
"${mpi[@]}" -np 2 "$lodforge" -v tiles scan.ply -o killed --chunk-size 60 --resume 2> resumed.err
taken=$(sed -nE 's/.*took ([0-9,]+) as the interrupted run left them.*/\1/p' resumed.err | tr -d ,)
[[ -n $taken && $taken -ge $done_before && $done_before -ge 3 ]] ||
  fail "--resume took ${taken:-no} nodes of the $done_before finished: $(cat resumed.err)"
same killed scan-1 "killed rank, then --resume"

# Two runs on one output: the second is refused (exit 2) while the first writes, which finishes.
# The first is held (SIGSTOP) once it has the output, until the second has tried; the refusal
# names it by its pid.
"$lodforge" -q tiles scan.ply -o busy --chunk-size 60 &
first=$!
hold $first busy.work/.lodforge-lock
set +e
"${mpi[@]}" -np 2 "$lodforge" -q tiles scan.ply -o busy --chunk-size 60 2> busy.err
code=$?
set -e
release $first
wait $first || fail "the first run failed"
[[ $code -eq 2 ]] || fail "a second run on a busy output exited $code, not 2"
grep -q "another lodforge run (pid $first on" busy.err || fail "no refusal naming the first run: $(cat busy.err)"
same busy scan-1 "the first run, beside the refused one"

# The same for a point cloud: a one-process run holds the output, a job of 2 is refused.
"$lodforge" -q tiles cloud.las -o busy-points --block-size 8000 &
first=$!
hold $first busy-points.work/.lodforge-lock
set +e
"${mpi[@]}" -np 2 "$lodforge" -q tiles cloud.las -o busy-points --block-size 8000 2> busy-points.err
code=$?
set -e
release $first
wait $first || fail "the first point run failed"
[[ $code -eq 2 ]] && grep -q "another lodforge run (pid $first on" busy-points.err ||
  fail "a point job on a busy output: exit $code, $(cat busy-points.err)"
[[ -f busy-points/tileset.json && ! -e busy-points.work ]] || fail "the first point run did not finish cleanly"

# --memory-limit holds per rank: each rank's peak (the -v lines rank 0 gathers) stays under it
# (not in the sanitizer tree, whose shadow memory the limit does not count: said, not hidden;
# there the scan above stands in for the 1 M one).
if [[ $sanitized == 1 ]]; then
  ln -s scan.ply limited.ply && ln -s scan-1 limited-1
else
  "$lodforge" -q generate scan --triangles 1M -o limited.ply
  "$lodforge" -q tiles limited.ply -o limited-1 --chunk-size 60
fi
"${mpi[@]}" -np 2 "$lodforge" -v --memory-limit 96M tiles limited.ply -o limited --chunk-size 60 \
  2> limited.err
[[ $sanitized == 1 ]] && echo "not checked in the sanitizer tree: each rank's peak memory"
for r in 0 1; do
  [[ $sanitized == 1 ]] && break
  peak=$(sed -nE "s/^rank $r: .*peak memory ([0-9.]+) MiB$/\1/p" limited.err)
  [[ -n $peak ]] && awk -v p="$peak" 'BEGIN { exit !(p < 96) }' ||
    fail "rank $r's peak memory ${peak:-unknown} MiB is not under --memory-limit 96M: $(cat limited.err)"
done
same limited limited-1 "2 ranks under --memory-limit 96M"

# Subcommands that do not run across ranks are refused, not run once per rank.
set +e
"${mpi[@]}" -np 2 "$lodforge" -q generate scan --triangles 1K -o twice.ply 2> twice.err
code=$?
set -e
[[ $code -eq 2 ]] && grep -q "only \`tiles\` and \`reconstruct\` run across" twice.err ||
  fail "generate under mpirun -np 2: exit $code, $(cat twice.err)"

finish distributed
