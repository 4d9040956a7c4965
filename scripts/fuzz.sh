#!/usr/bin/env bash
# Runs every reader's fuzzer for N seconds (default 20), two at a time, on its seed corpus plus
# the malformed-input corpus. New inputs go to build/fuzz/work (never into the repository);
# a crash, leak, timeout or out-of-memory leaves its input in build/fuzz/artifacts and fails
# (in fork mode, fuzz_cad's and fuzz_assimp's, a timeout or out-of-memory does not: see below).
set -euo pipefail
# OpenCASCADE's never-freed singletons are not findings (fuzz_cad).
export LSAN_OPTIONS=suppressions=$(cd "$(dirname "$0")/.." && pwd)/tests/lsan-suppressions.txt:print_suppressions=0
cd "$(dirname "$0")/.."
seconds=${1:-20}
# fuzz_cad runs in libFuzzer's fork mode, which goes on past an input that times out or runs out
# of memory and still fails on a crash, a leak or undefined behaviour: OCCT's BREP reader loops
# for minutes on some corrupt counts, which the wrapper cannot stop inside one process
# (docs/cad.md). fuzz_assimp is built and run by hand (READERS=assimp), in fork mode too: assimp
# allocates what a damaged count says, and a count past the machine's memory is a crash under
# ASan (its operator new cannot fail softly), while the release build reports std::bad_alloc as
# bad input (docs/io.md).
forked=" cad assimp "
readers=(${READERS:-ply obj stl gltf lfp png tiles las laz xyz lfc cad})
mkdir -p build/fuzz/artifacts
# The fuzzers' temporary files (an OBJ's folder, a CAD file per input) in a folder of this run,
# removed at the end: a job stopped at the time limit cannot remove its own.
export TMPDIR=$PWD/build/fuzz/tmp
rm -rf "$TMPDIR" && mkdir -p "$TMPDIR"
trap 'rm -rf "$TMPDIR"' EXIT
run() {
  local reader=$1 work=build/fuzz/work/$1 mode=() ignored="^$" passing="0" rc=0 replay=0
  # Past this, the run is stopped (`timeout` signals its whole process group, fork-mode jobs
  # included): a hang is then a failure, or let pass in fork mode (below).
  local wall=$((3 * seconds + 60))
  mkdir -p "$work"
  if [[ $forked == *" $reader "* ]]; then
    # Fork mode's first merge steps over a seed that crashes: replay the seeds in one process
    # first, so a crash found before (null-surface.iges) fails again.
    timeout -k 10 "$wall" build/asan/fuzz/fuzz_"$reader" -runs=0 -rss_limit_mb=2048 -timeout=10 \
      -artifact_prefix=build/fuzz/artifacts/"$reader"- fuzz/corpus/"$reader" tests/data/malformed \
      > build/fuzz/"$reader".log 2>&1 || replay=$?
    mode=(-fork=1 -ignore_timeouts=1 -ignore_ooms=1)
    # A fork-mode run exits with its last job's code even when it was let pass: 70 (timeout)
    # and 71 (out of memory). A fork-mode job that hangs inside libFuzzer's own timeout handler (seen once with
    # fuzz_cad: the child asleep on a futex after its "ALARM") would hold the run forever; the
    # wall-clock limit below ends it and, as for the library's timeouts, lets it pass (124, 137).
    ignored="oom-|timeout-" passing="0 70 71 124 137"
  fi
  timeout -k 10 "$wall" build/asan/fuzz/fuzz_"$reader" "${mode[@]}" -max_total_time="$seconds" -max_len=65536 \
    -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix=build/fuzz/artifacts/"$reader"- \
    "$work" fuzz/corpus/"$reader" tests/data/malformed >> build/fuzz/"$reader".log 2>&1 || rc=$?
  [ "$replay" -eq 0 ] || rc=1  # a seed that fails in one process fails whatever fork mode says
  if [[ " $passing " == *" $rc "* ]]; then
    local stopped=""
    [[ $rc == 124 || $rc == 137 ]] && stopped=" (stopped at the ${wall} s limit: a job hung)"
    echo "fuzz_$reader: $(summary build/fuzz/"$reader".log), no findings$stopped"
  else
    echo "fuzz_$reader FAILED; the report follows" >&2
    # The sanitizer's own report (what and where) first, then how libFuzzer ended.
    grep -m1 -A45 -E "ERROR: (AddressSanitizer|UndefinedBehaviorSanitizer|libFuzzer|LeakSanitizer)|runtime error:" \
      build/fuzz/"$reader".log >&2 || true
    tail -8 build/fuzz/"$reader".log >&2
    # The input itself, so a crash found on a CI machine can be replayed anywhere.
    for artifact in build/fuzz/artifacts/"$reader"-*; do
      [ -f "$artifact" ] && [ "$(stat -c %s "$artifact")" -le 65536 ] &&
        ! basename "$artifact" | grep -qE "^$reader-($ignored)" &&
        echo "$artifact (base64): $(base64 -w0 "$artifact")" >&2
    done
    return 1
  fi
}
# How many inputs ran; in fork mode also how many the library's own hangs and allocations cost.
summary() {
  local stats
  stats=$(grep -E '^#[0-9]+: cov:' "$1" | tail -1)
  if [ -n "$stats" ]; then
    echo "${stats%%:*} inputs (fork mode; out-of-memory/timeout in the library, let pass:" \
      "$(grep -oE 'oom/timeout/crash: [0-9]+/[0-9]+' <<< "$stats" | cut -d' ' -f2))" | tr -d '#'
  else
    echo "$(grep number_of_executed_units "$1" | tail -1 | awk '{print $2}') inputs"
  fi
}
status=0
for ((i = 0; i < ${#readers[@]}; i += 2)); do
  pids=()
  for reader in "${readers[@]:i:2}"; do
    run "$reader" & pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid" || status=1; done
done
exit $status
