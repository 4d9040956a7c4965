#!/usr/bin/env bash
# Configures and builds one of the project's builds under build/<name>:
#   release  optimised library, command, tests and benchmarks (g++)
#   asan     unit tests and command under AddressSanitizer + UndefinedBehaviorSanitizer (g++)
#   fuzz     one libFuzzer target per reader, with ASan + UBSan (clang++)
set -euo pipefail
cd "$(dirname "$0")/.."
name=${1:?usage: build.sh release|asan|fuzz}
jobs=${JOBS:-2}
# Clean clones (CI) reuse the compiler cache: paths are hashed relative to the checkout.
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=1
case $name in
  release) args=(-DCMAKE_BUILD_TYPE=Release) ;;
  asan) args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DLODFORGE_SANITIZE=ON -DLODFORGE_BENCH=OFF) ;;
  fuzz) args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DLODFORGE_FUZZ=ON -DLODFORGE_TESTS=OFF -DLODFORGE_APPS=OFF
              -DLODFORGE_BENCH=OFF -DCMAKE_CXX_COMPILER=clang++) ;;
  *) echo "unknown build '$name'" >&2; exit 2 ;;
esac
mkdir -p build
log=build/configure-$name.log
cmake -S . -B "build/$name" -G Ninja "${args[@]}" > "$log" 2>&1 || { cat "$log"; exit 1; }
cmake --build "build/$name" -j"$jobs"
# The browser viewers `lodforge serve` hands out (web/dist).
if [[ $name == release ]]; then scripts/build-web.sh; fi
