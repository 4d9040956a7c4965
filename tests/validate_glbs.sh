#!/usr/bin/env bash
# Every kind of GLB lodforge writes, checked by the Khronos glTF validator: conversions of the
# real models in ../shared/data, the generated CAD assembly, a generated scan, levels extracted
# from a progressive package, 3D Tiles contents (the horse, a scan, an assembly's package, point
# clouds from a LAS, a LAZ, a COPC, a LAS with extra bytes and a PLY, and a surface
# reconstructed from points), CAD files read through OpenCASCADE, and textured models.
# Fails on any error.
set -euo pipefail
lodforge=$1 data=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
validator="$here/js/node_modules/gltf-validator"
[[ -d $validator ]] || { echo "gltf-validator is not installed: run scripts/install-deps.sh" >&2; exit 1; }
rm -rf "$out" && mkdir -p "$out"
for model in "$data"/meshes/*; do
  name=$(basename "${model%.*}")
  "$lodforge" -q convert "$model" -o "$out/$name.glb"
done
"$lodforge" -q convert "$data/meshes/stanford-bunny.obj" -o "$out/bunny-welded.glb" --weld
"$lodforge" -q generate cad --objects 2000 --seed 5 -o "$out/cad.glb"
"$lodforge" -q generate scan --triangles 200K -o "$out/scan.ply"
"$lodforge" -q convert "$out/scan.ply" -o "$out/scan.glb"
"$lodforge" -q generate cad --objects 300 -o "$out/cad.ply"
"$lodforge" -q convert "$out/cad.ply" -o "$out/cad-from-ply.glb"
"$lodforge" -q build "$out/cad.glb" -o "$out/cad.lfp"
"$lodforge" -q extract "$out/cad.lfp" --ratio 0.25 -o "$out/cad-lod25.glb"
"$lodforge" -q extract "$out/cad.lfp" --ratio 0 -o "$out/cad-lod0.glb"
# CAD files through OpenCASCADE: a coloured STEP assembly and OCCT's IGES and BREP samples.
"$lodforge" -q convert "$data/cad/as1_motor.step" -o "$out/motor-step.glb"
"$lodforge" -q convert /usr/share/opencascade/data/iges/bearing.iges -o "$out/bearing-iges.glb"
"$lodforge" -q convert /usr/share/opencascade/data/occ/Ball.brep -o "$out/ball-brep.glb"
# Textured models: an OBJ whose MTL names five JPEGs, a GLB with an embedded PNG.
"$lodforge" -q convert "$data/textured/spider/spider.obj" -o "$out/spider-textured.glb"
"$lodforge" -q convert "$data/textured/BoxTextured.glb" -o "$out/box-textured.glb"
# A TGA texture (assimp's Collada duck): embedded as a PNG, glTF having no TGA.
"$lodforge" -q convert /usr/share/assimp/models/Collada/duck.dae -o "$out/duck-tga.glb"
count=$(ls "$out"/*.glb | wc -l)
want=$(( $(ls "$data"/meshes | wc -l) + 12 ))
[[ $count -eq $want ]] || { echo "expected $want GLBs, found $count" >&2; exit 1; }
"$lodforge" -q tiles "$data/meshes/horse.ply" -o "$out/horse-tiles" --chunk-size 0.05 --no-quantization
"$lodforge" -q tiles "$out/scan.ply" -o "$out/scan-tiles" --chunk-size 60 --compress meshopt
"$lodforge" -q tiles "$out/cad.lfp" -o "$out/cad-tiles"
"$lodforge" -q tiles "$data/cad/as1_motor.step" -o "$out/step-tiles" --chunk-size 20
# Point tiles: a real LAS (quantised, georeferenced) and generated points, float and meshopt.
# autzen plain, so the validator sees a point tile's accessor data (it does not look inside
# EXT_meshopt_compression, the point tiles' default).
"$lodforge" -q tiles "$data/points/autzen_trim.las" -o "$out/autzen-tiles" --block-size 20K --tile-points 10K \
  --compress none
"$lodforge" -q tiles "$data/points/autzen_trim.laz" -o "$out/autzen-laz-tiles" --block-size 20K --tile-points 10K
"$lodforge" -q tiles "$data/points/1.2-with-color.copc.laz" -o "$out/copc-tiles" --block-size 500
"$lodforge" -q generate points --points 30K --extra-bytes -o "$out/extra.las"
"$lodforge" -q tiles "$out/extra.las" -o "$out/extra-tiles" --block-size 10K
"$lodforge" -q generate points --points 60K -o "$out/points.ply"
"$lodforge" -q tiles "$out/points.ply" --surface -o "$out/surface-tiles" --chunk-size 100
"$lodforge" -q tiles "$out/points.ply" -o "$out/points-tiles" --block-size 10K --no-quantization --compress meshopt
# Textured tiles: charts re-baked into each tile's own pages (JPEG, and WebP for the box).
"$lodforge" -q tiles "$data/textured/spider/spider.obj" -o "$out/spider-tiles" --chunk-size 40
"$lodforge" -q tiles "$data/textured/BoxTextured.glb" -o "$out/box-tiles" --texture-format webp
# A generated textured scan (MeshLab's textured PLY: four JPEG atlases), streamed.
"$lodforge" -q generate scan --triangles 20K --texture 256 --atlases 4 -o "$out/scan-textured.ply"
"$lodforge" -q tiles "$out/scan-textured.ply" -o "$out/scan-textured-tiles" --chunk-size 150
# Textured levels out of a progressive package (its images embedded in the package).
"$lodforge" -q build "$out/scan-textured.ply" -o "$out/scan-textured.lfp"
"$lodforge" -q extract "$out/scan-textured.lfp" --ratio 0.2 -o "$out/scan-textured-lod20.glb"
"$lodforge" -q build "$data/textured/spider/spider.obj" -o "$out/spider.lfp"
"$lodforge" -q extract "$out/spider.lfp" --ratio 0 -o "$out/spider-lod0.glb"
tiles=$(ls "$out"/horse-tiles/tiles/*.glb "$out"/scan-tiles/tiles/*.glb | wc -l)
[[ $tiles -ge 20 ]] || { echo "expected at least 20 tile GLBs, found $tiles" >&2; exit 1; }
node "$here/js/validate-gltf.mjs" "$out"/*.glb "$out"/horse-tiles/tiles/*.glb "$out"/scan-tiles/tiles/*.glb \
  "$out"/cad-tiles/tiles/*.glb "$out"/autzen-tiles/tiles/*.glb "$out"/points-tiles/tiles/*.glb \
  "$out"/autzen-laz-tiles/tiles/*.glb "$out"/copc-tiles/tiles/*.glb "$out"/extra-tiles/tiles/*.glb \
  "$out"/surface-tiles/tiles/*.glb "$out"/step-tiles/tiles/*.glb "$out"/spider-tiles/tiles/*.glb \
  "$out"/box-tiles/tiles/*.glb "$out"/scan-textured-tiles/tiles/*.glb
