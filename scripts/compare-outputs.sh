#!/usr/bin/env bash
# Compares what two lodforge binaries write for the same inputs, byte for byte: tilesets (meshes,
# assemblies, point clouds from LAS, LAZ, COPC and XYZ, a STEP assembly, a reconstructed surface),
# a reconstructed mesh, packages and extracts. For refactors that must not change output.
#   scripts/compare-outputs.sh OLD_BINARY NEW_BINARY [WORK_DIR]
# Point packages carry a random build id (and a checksum over it): up to 16 differing bytes per
# .lfc/.seg file are expected, as between two runs of one binary.
set -euo pipefail
old=${1:?usage: compare-outputs.sh OLD_BINARY NEW_BINARY [WORK_DIR]}
new=${2:?usage: compare-outputs.sh OLD_BINARY NEW_BINARY [WORK_DIR]}
work=${3:-$(mktemp -d)}
old=$(realpath "$old") new=$(realpath "$new")
data=$(cd "$(dirname "$0")/.." && pwd)/../shared/data
run() {
  local L=$1 D=$2
  rm -rf "$D" && mkdir -p "$D" && cd "$D"
  "$L" -q generate scan --triangles 300K -o scan.ply
  "$L" -q generate cad --objects 300 -o cad.glb
  "$L" -q generate cad --objects 300 -o cadids.ply
  "$L" -q tiles scan.ply -o scan-tiles
  "$L" -q --threads 1 tiles scan.ply -o scan1-tiles --chunk-size 20
  "$L" -q tiles cad.glb -o cad-tiles
  "$L" -q tiles cadids.ply -o cadids-tiles
  "$L" -q tiles "$data/meshes/horse.ply" -o horse-tiles
  "$L" -q tiles "$data/meshes/as1_motor.glb" -o motor-tiles --levels 3
  "$L" -q tiles "$data/points/autzen_trim.las" -o autzen-tiles
  "$L" -q tiles "$data/points/simple.las" -o simple-tiles --origin 7,50,10
  "$L" -q tiles "$data/points/kitten.xyz" -o kitten-tiles
  "$L" -q tiles "$data/points/autzen_trim.laz" -o autzen-laz-tiles
  "$L" -q tiles "$data/points/1.2-with-color.copc.laz" -o copc-tiles
  "$L" -q tiles "$data/cad/as1_motor.step" -o step-tiles
  "$L" -q --threads 1 tiles "$data/points/autzen_trim.laz" --surface -o surface-tiles --voxel 4
  "$L" -q reconstruct "$data/points/kitten.xyz" -o kitten-surface.ply
  "$L" -q build cad.glb -o cad.lfp
  "$L" -q build "$data/meshes/horse.ply" -o horse.lfp
  "$L" -q extract cad.lfp --error 0.01 -o cad-e.ply
  "$L" -q extract cad.lfp --ratio 0.3 -o cad-r.glb
  "$L" -q points "$data/points/autzen_trim.las" -o autzen.lfc
  rm -f scan.ply cad.glb cadids.ply
}
(run "$old" "$work/old")
(run "$new" "$work/new")
status=0
while IFS= read -r file; do
  a="$work/old/$file" b="$work/new/$file"
  if [[ ! -f $b ]]; then echo "missing in new: $file"; status=1; continue; fi
  case $file in
    *.lfc | *.seg)
      differing=$( (cmp -l "$a" "$b" 2>/dev/null || true) | wc -l)
      if [[ $(stat -c %s "$a") != $(stat -c %s "$b") || $differing -gt 16 ]]; then
        echo "differs: $file ($differing bytes)"; status=1
      fi ;;
    *) cmp -s "$a" "$b" || { echo "differs: $file"; status=1; } ;;
  esac
done < <(cd "$work/old" && find . -type f | sort)
[[ $(cd "$work/old" && find . -type f | wc -l) == $(cd "$work/new" && find . -type f | wc -l) ]] ||
  { echo "the two wrote different sets of files"; status=1; }
((status == 0)) && echo "identical: $(cd "$work/old" && find . -type f | wc -l) files ($work)"
exit $status
