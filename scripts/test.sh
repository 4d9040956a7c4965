#!/usr/bin/env bash
# `make test`: the release build and every test; the unit and CLI tests again under ASan +
# UBSan; every fuzzer for FUZZ_SECONDS (default 20) on its seed corpus and the malformed corpus.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${JOBS:-2}
fuzz_seconds=${FUZZ_SECONDS:-20}
started=$SECONDS
step() { printf '\n== %s (%d s so far)\n' "$*" $((SECONDS - started)); }

step "release build"
scripts/build.sh release
step "tests (release)"
ctest --test-dir build/release -j"$jobs" --output-on-failure

step "sanitizer build (ASan + UBSan)"
scripts/build.sh asan
step "tests (ASan + UBSan)"
# intercept_tls_get_addr=0: GCC 12's runtime mistakes some of Mesa's dynamic TLS blocks for a
# pre-2.25 glibc header, and LeakSanitizer's tracer then crashes at exit, now and then.
ASAN_OPTIONS=abort_on_error=1:detect_leaks=1:intercept_tls_get_addr=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  LSAN_OPTIONS=suppressions=$PWD/tests/lsan-suppressions.txt:print_suppressions=0 \
  ctest --test-dir build/asan -j"$jobs" --output-on-failure

step "fuzzers (${fuzz_seconds} s each)"
scripts/build.sh fuzz
scripts/fuzz.sh "$fuzz_seconds"

step "all tests passed"
