# What the MPI test scripts share (sourced by mpi_tiles.sh and mpi_reconstruct.sh): OpenMPI's
# mpirun as the tests run it, and the failures counted.
command -v mpirun >/dev/null || { echo "mpirun is not installed: run scripts/install-deps.sh" >&2; exit 1; }
# --allow-run-as-root: CI runs as root, which OpenMPI otherwise refuses. --oversubscribe: more
# ranks than this machine's cores. In the sanitizer tree the ranks run without LeakSanitizer:
# OpenMPI's components are loaded and unloaded at run time and leave allocations it can only
# attribute to "<unknown module>" (ours are checked by every other test, which runs the same
# code in one process).
# --mca pml ob1: OpenMPI's own point-to-point layer, which between the ranks of one machine sends
# through shared memory; OpenMPI's own choice of a layer took 0.25 s of every mpirun here (in a
# release and a sanitizer run alike), and the scripts start about fifty jobs. lodforge asks for
# ob1 itself when every rank is on one machine and no layer was chosen (src/lodforge/core/
# cluster.cpp): mpi_default leaves that choice to it for one check.
mpi_default=(env "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" mpirun --allow-run-as-root --oversubscribe)
mpi=("${mpi_default[@]}" --mca pml ob1)
# For a job with a rank killed on purpose: mpirun sends the others SIGTERM and, one second later
# (odls_base_sigkill_timeout), SIGKILL. A rank in the middle of a step reaches its next check
# for the SIGTERM later than that when the machine is loaded (sanitizer tree: two of eight runs
# of mpi_reconstruct.sh), and was killed before it said what the others were doing. 3 s: mpirun
# also waits that long before the SIGTERM, so such a job ends 2 × 3 s after the kill (10 s made
# the two scripts 25–35 s slower).
mpi_killed=("${mpi[@]}" --mca odls_base_sigkill_timeout 3)
# The rank counts each output is compared at: every one given in the release tree (1, a job of
# one, to 4); in the sanitizer tree, whose runs are several times slower, 3 alone (the same code
# for any count, with work that does not divide evenly; what differs between counts is checked
# in the release tree).
rank_counts() { if [[ ${sanitized:-0} == 1 ]]; then echo 3; else echo "$@"; fi; }
failures=0
# hold PID LOCK: once the run PID holds its output (its lock file LOCK is written), stops it
# (SIGSTOP) until `release PID`, so that a second run meets it whatever its speed; the script
# never leaves it stopped.
hold() {
  local _
  for _ in $(seq 3000); do [[ -s $2 ]] && break; sleep 0.02; done
  [[ -s $2 ]] || { fail "no lock $2 after 60 s"; return; }
  kill -STOP "$1" || fail "the run $1 ended before it was held"
  trap "kill -CONT $1 2>/dev/null || true" EXIT
}
release() { kill -CONT "$1" 2>/dev/null || true; trap - EXIT; }
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
same() {  # same OUTPUT REFERENCE WHAT: a tileset (folder) or a mesh (file), byte for byte
  if diff -r "$1" "$2" >/dev/null; then echo "ok: $3"; else fail "$3: $1 differs from $2"; diff -rq "$1" "$2" | head -5 >&2; fi
}
finish() {  # the verdict, last
  [[ $failures -eq 0 ]] || { echo "$failures failure(s)" >&2; exit 1; }
  echo "all $1 checks passed"
}
