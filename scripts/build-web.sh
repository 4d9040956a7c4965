#!/usr/bin/env bash
# Builds the browser viewers (web/: CesiumJS and three.js pages, Vite) into web/dist, where
# `lodforge serve` finds them. Skips the build when dist is newer than every source.
set -euo pipefail
cd "$(dirname "$0")/../web"
[[ -d node_modules ]] || { echo "web/node_modules is missing: run scripts/install-deps.sh" >&2; exit 1; }
if [[ -f dist/cesium/index.html && -f dist/three/index.html ]]; then
  newer=$(find cesium three format.js point_colors.js parts_panel.js panel.css vite.config.js package-lock.json -newer dist/cesium/index.html | head -1)
  [[ -z $newer ]] && exit 0
fi
echo "build-web: vite build into web/dist"
npm run --silent build
