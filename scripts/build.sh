#!/usr/bin/env bash
# Configures and builds one of the project's builds under build/<name>:
#   release  optimised library, command, tests and benchmarks (g++)
#   asan     the sanitizer tree (clang++): the unit tests, the command and one libFuzzer target
#            per reader, all under AddressSanitizer + UndefinedBehaviorSanitizer (the fuzzers
#            against a copy of the library with libFuzzer's coverage, the rest without it)
#            (line tables only: a report still names file and line, at a fraction of -g's cost)
set -euo pipefail
cd "$(dirname "$0")/.."
name=${1:?usage: build.sh release|asan}
jobs=${JOBS:-2}
# Clean clones (CI) reuse the compiler cache: paths are hashed relative to the checkout. 10 GB
# holds both trees' objects with room for earlier versions of them.
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=1 CCACHE_MAXSIZE=${CCACHE_MAXSIZE:-10G}
case $name in
  release) args=(-DCMAKE_BUILD_TYPE=Release) ;;
  asan) args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only"
              -DLODFORGE_SANITIZE=ON -DLODFORGE_FUZZ=ON -DLODFORGE_BENCH=OFF -DCMAKE_CXX_COMPILER=clang++) ;;
  *) echo "unknown build '$name'" >&2; exit 2 ;;
esac
mkdir -p build
log=build/configure-$name.log
cmake -S . -B "build/$name" -G Ninja "${args[@]}" > "$log" 2>&1 || { cat "$log"; exit 1; }
cmake --build "build/$name" -j"$jobs"
# The browser viewers `lodforge serve` hands out (web/dist).
if [[ $name == release ]]; then scripts/build-web.sh; fi
