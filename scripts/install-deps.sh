#!/usr/bin/env bash
# Installs what lodforge needs to build, test and benchmark on Debian 12, and nothing else.
# Idempotent: when everything is present it only checks (a few seconds) and changes nothing.
# The only place in the project that installs packages.
set -euo pipefail

here=$(cd "$(dirname "$0")/.." && pwd)

# Debian packages named in docs/DEPENDENCIES.md (DESIGN.md's list plus the build tools).
packages=(
  # toolchain
  build-essential cmake ninja-build ccache clang libclang-rt-14-dev clang-format pkg-config time
  # libraries
  libtbb-dev nlohmann-json3-dev libcli11-dev libspdlog-dev libfmt-dev libtinygltf-dev
  libtinyobjloader-dev libmeshoptimizer-dev libdraco-dev libnanoflann-dev libeigen3-dev libproj-dev
  libstb-dev libcpp-httplib-dev zlib1g-dev libxxhash-dev
  # textures: JPEG (libjpeg-turbo) and WebP codecs; Debian's textured test models
  libjpeg62-turbo-dev libwebp-dev assimp-testmodels
  # CAD: OpenCASCADE's data exchange (STEP, IGES, BREP through XDE); fontconfig is a link
  # dependency of its CMake config; occt-misc holds its sample files, used as test data
  libocct-data-exchange-dev libfontconfig1-dev occt-misc
  # interchange formats (OFF, FBX, Collada, 3DS, IFC, …) through assimp
  libassimp-dev
  # builds across machines: OpenMPI (mpirun; Slurm's srun launches it as it is)
  libopenmpi-dev openmpi-bin
  # rendering (headless EGL on Mesa's llvmpipe, GLFW window, Dear ImGui)
  libepoxy-dev libegl-dev libgl1-mesa-dri libglfw3-dev libimgui-dev xvfb
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev chromium wrk
)

missing=()
for p in "${packages[@]}"; do
  # dpkg-query is fast; a package counts as present only when fully installed
  status=$(dpkg-query -W -f='${db:Status-Abbrev}' "$p" 2>/dev/null || true)
  [[ "$status" == ii* ]] || missing+=("$p")
done
# Node.js may come from Debian (nodejs + npm) or from elsewhere; accept either.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  missing+=(nodejs npm)
fi

if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# npm packages, pinned by package-lock.json: the test tools (glTF validator, playwright-core) and
# the browser viewers (web/: cesium, three, 3d-tiles-renderer, vite). `npm ci` only when
# node_modules is missing or older than the lock file.
for js in "$here/tests/js" "$here/web"; do
  if [[ -f "$js/package-lock.json" ]]; then
    stamp="$js/node_modules/.package-lock.json"
    if [[ ! -f "$stamp" || "$js/package-lock.json" -nt "$stamp" ]]; then
      echo "install-deps: npm ci in ${js#"$here"/}"
      (cd "$js" && npm ci --no-audit --no-fund --loglevel=error)
    fi
  fi
done
