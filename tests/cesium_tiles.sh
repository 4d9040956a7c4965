#!/usr/bin/env bash
# Tilesets lodforge writes, loaded by CesiumJS in Debian's headless chromium from a local HTTP
# server (tests/js/cesium-tiles.mjs): a generated scan, georeferenced with --origin, its contents
# meshopt-compressed and with KHR_mesh_quantization (the default), the same scan with implicit
# tiling, and a generated 2,000-part assembly (tiled by part, colours per part). Fails on any tile
# failure, failed request or console error, or if the screenshot does not show the model. The
# horse (meshopt-compressed, and uncompressed with implicit tiling) and a LAS point cloud placed
# from its own coordinate system (the same command) go through the same CesiumJS in
# tests/web_viewers.sh, at that viewer's screen-space error (16, not 4).
set -euo pipefail
lodforge=$1 out=$2
here=$(cd "$(dirname "$0")" && pwd)
for package in cesium playwright-core; do
  [[ -d $here/js/node_modules/$package ]] ||
    { echo "$package is not installed: run scripts/install-deps.sh" >&2; exit 1; }
done
[[ -x /usr/bin/chromium ]] || { echo "chromium is not installed: run scripts/install-deps.sh" >&2; exit 1; }
rm -rf "$out" && mkdir -p "$out"
"$lodforge" -q generate scan --triangles 200K -o "$out/scan.ply"
"$lodforge" -q tiles "$out/scan.ply" -o "$out/scan" --chunk-size 150 --compress meshopt \
  --origin -122.4,37.8,10
node "$here/js/cesium-tiles.mjs" "$out/scan" "$out/scan.png" --min-coverage 0.2
# The same scan with implicit tiling (subtree files, errors and boxes as tile metadata): CesiumJS
# must fetch the same contents and draw the same picture.
"$lodforge" -q tiles "$out/scan.ply" -o "$out/scan-implicit" --chunk-size 150 --compress meshopt \
  --origin -122.4,37.8,10 --implicit-tiling on
node "$here/js/cesium-tiles.mjs" "$out/scan-implicit" "$out/scan-implicit.png" --min-coverage 0.2 \
  --same-as "$out/scan.png"
"$lodforge" -q generate cad --objects 2000 --seed 5 -o "$out/cad.glb"
"$lodforge" -q tiles "$out/cad.glb" -o "$out/cad" --origin 2.35,48.85,35
node "$here/js/cesium-tiles.mjs" "$out/cad" "$out/cad.png" --min-coverage 0.05
