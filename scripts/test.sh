#!/usr/bin/env bash
# `make test`: installs what is missing, the release build and every test; the unit and CLI tests
# again in the sanitizer tree (ASan + UBSan, clang), whose fuzzers then run FUZZ_SECONDS each
# (default 20) on their seed corpus and the malformed corpus. The browsers, the glTF validator,
# laz-perf and the docs check look at what the release binary writes, once: the sanitizer tree
# would only run them again slower. Ends with a table of where the time went, also written to
# build/test-times.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${JOBS:-2}
fuzz_seconds=${FUZZ_SECONDS:-20}
started=$SECONDS
phase_started=$SECONDS
phases=()
mkdir -p build
# Each phase's seconds and, for a test run, its five slowest tests.
step() { printf '\n== %s (%d s so far)\n' "$*" $((SECONDS - started)); phase_started=$SECONDS; }
done_step() { phases+=("$1|$((SECONDS - phase_started))|${2:-}"); }
slowest() {
  grep -E '^ *[0-9]+/[0-9]+ Test +#[0-9]+: ' "$1" | sed -E 's/.*Test +#[0-9]+: ([^ ]+) .* ([0-9.]+) sec$/\2 \1/' |
    sort -rn | head -5 | awk '{printf "%s%s %.0f", (NR > 1 ? ", " : ""), $2, $1}'
}
table() {
  local total=$((SECONDS - started)) row name secs detail
  {
    printf '\n| phase | seconds | share | slowest |\n|---|---:|---:|---|\n'
    for row in "${phases[@]}"; do
      IFS='|' read -r name secs detail <<< "$row"
      printf '| %s | %d | %d %% | %s |\n' "$name" "$secs" $((100 * secs / (total > 0 ? total : 1))) "$detail"
    done
    printf '| **total** | **%d** | 100 %% | %s |\n' "$total" "$1"
  } | tee build/test-times.txt
}
trap 'status=$?; table "$([ $status -eq 0 ] && echo "all passed" || echo "FAILED (exit $status)")"' EXIT

step "install check"
scripts/install-deps.sh
done_step "install check"

step "release build"
scripts/build.sh release
done_step "release build"

step "tests (release)"
ctest --test-dir build/release -j"$jobs" --output-on-failure | tee build/ctest-release.log
done_step "tests (release)" "$(slowest build/ctest-release.log)"

step "sanitizer build (ASan + UBSan, tests and fuzzers)"
scripts/build.sh asan
done_step "sanitizer build"

step "tests (ASan + UBSan)"
# intercept_tls_get_addr=0: the sanitizer runtime mistakes some of Mesa's dynamic TLS blocks for
# a pre-2.25 glibc header, and LeakSanitizer's tracer then crashes at exit, now and then.
ASAN_OPTIONS=abort_on_error=1:detect_leaks=1:intercept_tls_get_addr=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  LSAN_OPTIONS=suppressions=$PWD/tests/lsan-suppressions.txt:print_suppressions=0 \
  ctest --test-dir build/asan -j"$jobs" --output-on-failure -LE "browser|validator|docs" |
  tee build/ctest-asan.log
done_step "tests (ASan + UBSan)" "$(slowest build/ctest-asan.log)"

step "fuzzers (${fuzz_seconds} s each)"
scripts/fuzz.sh "$fuzz_seconds"
done_step "fuzzers"

step "all tests passed"
