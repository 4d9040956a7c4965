#!/usr/bin/env bash
# `make demo`: generates a CAD assembly and a scanned surface, reads them and the real models in
# ../shared/data, prints `lodforge info` for each, builds progressive packages, times budgeted
# selection and streaming along an orbit, renders frames headless at three budgets and full
# detail with their image difference, writes 3D Tiles of the scan and of a real LAS point cloud,
# and writes GLBs, PNGs and JSON under out/demo/; it ends with the `lodforge serve` command.
set -euo pipefail
cd "$(dirname "$0")/.."
lodforge=build/release/lodforge
out=out/demo
data=${LODFORGE_DATA:-../shared/data}
[[ -d $data ]] || data=/work/shared/data
mkdir -p "$out"

section() { printf '\n== %s\n' "$*"; }

section "generating a 10,000-part CAD assembly and a 1M-triangle scan"
"$lodforge" generate cad --objects 10K --seed 1 -o "$out/cad-assembly.glb"
"$lodforge" generate scan --triangles 1M --seed 1 -o "$out/scan.ply"
"$lodforge" convert "$out/scan.ply" -o "$out/scan.glb"
"$lodforge" generate points --points 1M --seed 1 -o "$out/points.ply"

for model in "$out/cad-assembly.glb" "$out/scan.ply" "$out/points.ply"; do
  section "lodforge info $model"
  "$lodforge" info "$model"
done

section "progressive meshes for every part of the assembly, and two levels out of them"
"$lodforge" build "$out/cad-assembly.glb" -o "$out/cad-assembly.lfp"
"$lodforge" info "$out/cad-assembly.lfp"
"$lodforge" extract "$out/cad-assembly.lfp" --ratio 0.25 -o "$out/cad-assembly-25pct.glb"
section "budgeted LOD selection and coherent streaming along an orbit (the CAD paper's Table 1 on the CPU)"
"$lodforge" bench "$out/cad-assembly.lfp" --frames 60 --budget 5%,20%,50% --json "$out/bench.json" \
  --record-path "$out/orbit-path.json"
# Frames of a package along an orbit that fills the picture with the model (render's default
# path), at full detail and at budgets of 1, 5 and 20 %, each budget compared with full detail.
render_budgets() {
  local package=$1 frames=$2
  "$lodforge" render "$package" --frames 6 --reference -o "$frames/reference"
  for budget in 1 5 20; do
    "$lodforge" render "$package" --frames 6 --budget "$budget%" -o "$frames/budget-$budget"
  done
  for budget in 1 5 20; do
    echo
    echo "budget $budget % against the full-detail frames (CIE76 ΔE, the share above 2.3 is visible):"
    "$lodforge" compare "$frames/reference" "$frames/budget-$budget" \
      --diff "$frames/difference-$budget" --json "$frames/compare-$budget.json"
  done
}
section "headless renders: the generated assembly and a real one (the STEP motor), full detail and budgets of 1 %, 5 % and 20 %, compared"
render_budgets "$out/cad-assembly.lfp" "$out/render/assembly"
if [[ -f $data/cad/as1_motor.step ]]; then
  "$lodforge" build "$data/cad/as1_motor.step" -o "$out/as1-motor.lfp"
  render_budgets "$out/as1-motor.lfp" "$out/render/motor"
fi
"$lodforge" build "$out/scan.ply" -o "$out/scan.lfp"
"$lodforge" extract "$out/scan.lfp" --ratio 0.02 -o "$out/scan-2pct.glb"

if [[ -d $data/meshes ]]; then
  for model in "$data"/meshes/*; do
    name=$(basename "${model%.*}")
    section "lodforge info $model"
    "$lodforge" info "$model"
    "$lodforge" convert "$model" -o "$out/$name.glb"
  done
else
  echo "(no real models: $data/meshes not found)"
fi

section "3D Tiles: the scan (mesh) and a real LAS point cloud (placed on Earth from its CRS)"
"$lodforge" tiles "$out/scan.ply" -o "$out/tiles/scan" --origin 8.5417,47.3769,408 --compress meshopt
if [[ -f $data/points/autzen_trim.las ]]; then
  "$lodforge" info "$data/points/autzen_trim.las"
  "$lodforge" points "$data/points/autzen_trim.las" -o "$out/autzen.lfc"
  "$lodforge" tiles "$data/points/autzen_trim.las" -o "$out/tiles/autzen" --tile-points 20K
fi

section "results"
ls -l "$out"
echo
echo "The GLBs in $(pwd)/$out open in any glTF 2.0 viewer (Blender, the three.js editor, ...)."
echo "Frames: $(pwd)/$out/render/assembly and .../motor (reference, budget-1/5/20 side by side,"
echo "difference heat maps)."
echo "Interactive: $lodforge view $out/cad-assembly.lfp   (needs a display)"
echo "Point package: $lodforge view $out/autzen.lfc   (needs a display; the fovea follows the mouse)"
echo
echo "In a browser (CesiumJS and three.js viewers, nothing fetched from the internet):"
echo "  $lodforge serve $out/tiles/scan --port 8080"
echo "  then open http://127.0.0.1:8080/cesium/  or  http://127.0.0.1:8080/three/"
echo "  (the point cloud: $lodforge serve $out/tiles/autzen --port 8080)"
