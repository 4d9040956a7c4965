#!/bin/bash
# scripts/slurm-check.sh LODFORGE [WORK]: the checks of docs/distributed.md ("Slurm") on a machine
# where Slurm runs (sinfo answers) and srun has PMIx (`--mpi=pmix`). Not part of `make test`: the
# test machines have no Slurm; docs/distributed.md says how it was set up and what this gave.
# A job of 2 tasks through sbatch (the documented job script, scaled down) must write the
# tileset and the mesh one process writes; tasks srun starts with no MPI plugin must say they work
# alone; a point
# job whose task 1 dies must stop, keep its work and resume with 3 tasks to the same tileset.
set -euo pipefail
lodforge=$(realpath "$1")
work=${2:-$(mktemp -d)}
mkdir -p "$work" && cd "$work"
sinfo > /dev/null || { echo "slurm-check: no Slurm here (sinfo fails)" >&2; exit 2; }
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }
same() { if diff -r "$1" "$2" > /dev/null; then echo "ok: $3"; else fail "$3: $1 differs from $2"; fi; }

"$lodforge" -q generate scan --triangles 200K -o scan.ply
"$lodforge" -q generate points --points 100K -o cloud.ply
"$lodforge" -q generate points --points 400K --extra-bytes -o large.las
"$lodforge" -q tiles scan.ply -o scan-1 --chunk-size 60
"$lodforge" -q --threads 1 --memory-limit 256M reconstruct cloud.ply -o cloud-1.ply

cat > job.sh << JOB
#!/bin/bash
#SBATCH --job-name=tiles
#SBATCH --nodes=1
#SBATCH --ntasks-per-node=2
#SBATCH --cpus-per-task=1
#SBATCH --output=job-%j.out
srun --mpi=pmix --kill-on-bad-exit=1 "$lodforge" --threads \$SLURM_CPUS_PER_TASK \\
  tiles scan.ply -o scan-slurm --chunk-size 60
srun --mpi=pmix --kill-on-bad-exit=1 "$lodforge" --threads \$SLURM_CPUS_PER_TASK \\
  --memory-limit 256M reconstruct cloud.ply -o cloud-slurm.ply
JOB
sbatch --wait job.sh > /dev/null || fail "the job script failed: $(cat job-*.out)"
same scan-slurm scan-1 "mesh tileset, sbatch, 2 tasks"
cmp -s cloud-slurm.ply cloud-1.ply && echo "ok: reconstruction, sbatch, 2 tasks" ||
  fail "the reconstruction by 2 tasks differs"

# (two tasks, each its own output, as tasks started on purpose for separate work are)
srun -n 2 --mpi=none bash -c '"$0" -q tiles large.las -o "none-$SLURM_PROCID"' "$lodforge" \
  > none.out 2> none.err || fail "two separate tasks failed: $(cat none.err)"
[[ -d none-0 && -d none-1 ]] || fail "two separate tasks did not write their tilesets"
[[ $(grep -c "each task works alone (\`srun --mpi=pmix\`" none.err) == 2 ]] &&
  echo "ok: tasks srun started with no MPI plugin say they work alone" ||
  fail "srun --mpi=none said nothing: $(cat none.err)"

# The tests' knob: 16 nodes of the partition, so that task 1 has some to die in.
export LODFORGE_PARTITION_BYTES=4000000
"$lodforge" -q tiles large.las -o large-1 --block-size 10000
cat > task1-dies.sh << DIES
#!/bin/bash
[[ \$SLURM_PROCID == 1 ]] && export LODFORGE_INTERRUPT_AFTER=pointnode:2:kill
exec "$lodforge" "\$@"
DIES
chmod +x task1-dies.sh
set +e
srun -n 2 --mpi=pmix --kill-on-bad-exit=1 ./task1-dies.sh tiles large.las -o killed \
  --block-size 10000 > killed.out 2> killed.err
code=$?
set -e
[[ $code -ne 0 ]] && grep -q "the finished work is kept in killed.work" killed.err &&
  echo "ok: a task killed, the job stopped, the work kept" || fail "the kill: $(cat killed.err)"
srun -n 3 -O --mpi=pmix --kill-on-bad-exit=1 "$lodforge" -v tiles large.las -o killed \
  --block-size 10000 --resume 2> resumed.err
grep "resumed:" resumed.err || fail "nothing resumed: $(cat resumed.err)"
same killed large-1 "point tileset, task killed, --resume by 3 tasks"
[[ $failures -eq 0 ]] || { echo "$failures failure(s)" >&2; exit 1; }
echo "all Slurm checks passed (in $work)"
