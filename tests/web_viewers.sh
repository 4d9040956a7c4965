#!/usr/bin/env bash
# The browser viewers end to end (tests/js/web-viewers.mjs): `lodforge serve` on a free loopback
# port, the CesiumJS and the three.js page in headless chromium, for a mesh tileset (the horse,
# georeferenced, meshopt-compressed, and again with implicit tiling), a point tileset (a LAS
# placed from its own CRS) and the surface reconstructed from a LAZ scan (tiles --surface, placed
# from the file's CRS), and a STEP assembly whose parts are picked, found, highlighted and hidden
# in both viewers, and a generated STEP assembly whose parts are also hidden by CAD layer, and a
# textured OBJ (a red and blue checker) whose texture both viewers must draw.
set -euo pipefail
lodforge=$1 data=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
[[ -f $here/../web/dist/cesium/index.html && -f $here/../web/dist/three/index.html ]] ||
  { echo "the viewers are not built: run scripts/build-web.sh (make does)" >&2; exit 1; }
[[ -d $here/js/node_modules/playwright-core ]] ||
  { echo "playwright-core is not installed: run scripts/install-deps.sh" >&2; exit 1; }
rm -rf "$out" && mkdir -p "$out/horse-shots" "$out/autzen-shots" "$out/surface-shots" "$out/motor-shots" \
  "$out/layers-shots" "$out/checker-shots"
"$lodforge" -q tiles "$data/meshes/horse.ply" -o "$out/horse" --chunk-size 0.05 \
  --origin 8.5417,47.3769,408 --compress meshopt
node "$here/js/web-viewers.mjs" "$lodforge" "$out/horse" "$out/horse-shots" --min-coverage 0.03
# The horse again with implicit tiling (subtree files; the three.js page reads their metadata, so
# both viewers take the same errors and draw the same triangles).
mkdir -p "$out/horse-implicit-shots"
"$lodforge" -q tiles "$data/meshes/horse.ply" -o "$out/horse-implicit" --chunk-size 0.02 \
  --origin 8.5417,47.3769,408 --implicit-tiling on
node "$here/js/web-viewers.mjs" "$lodforge" "$out/horse-implicit" "$out/horse-implicit-shots" \
  --min-coverage 0.03 --same-drawn
"$lodforge" -q tiles "$here/data/textured/checker-plane.obj" -o "$out/checker" --chunk-size 30 \
  --origin 8.5417,47.3769,408
node "$here/js/web-viewers.mjs" "$lodforge" "$out/checker" "$out/checker-shots" --min-coverage 0.1 \
  --texture-hues 0.2
"$lodforge" -q tiles "$data/points/autzen_trim.las" -o "$out/autzen" --block-size 20K --tile-points 10K
node "$here/js/web-viewers.mjs" "$lodforge" "$out/autzen" "$out/autzen-shots" --min-coverage 0.03
"$lodforge" -q tiles "$data/points/autzen_trim.laz" --surface -o "$out/surface" --voxel 4 --chunk-size 100
node "$here/js/web-viewers.mjs" "$lodforge" "$out/surface" "$out/surface-shots" --min-coverage 0.03
"$lodforge" -q tiles "$data/cad/as1_motor.step" -o "$out/motor" --origin 2.35,48.85,35
node "$here/js/web-viewers.mjs" "$lodforge" "$out/motor" "$out/motor-shots" --min-coverage 0.03
"$lodforge" -q generate cad --objects 200 -o "$out/layers.step"
"$lodforge" -q tiles "$out/layers.step" -o "$out/layers"
# 200 parts spread over a 64 m airframe: little of the view is covered.
node "$here/js/web-viewers.mjs" "$lodforge" "$out/layers" "$out/layers-shots" --min-coverage 0.0003
