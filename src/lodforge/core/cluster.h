// The processes of one job that mpirun or Slurm's srun started (docs/distributed.md): which one
// this is, how many there are, and the one collective step the pipelines take between their
// stages, everyone's outcome. A process started any other way, or built without MPI
// (LODFORGE_MPI=OFF), is a job of one and behaves exactly as a plain run.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "lodforge/core/status.h"

namespace lodforge {

// Joins the job when an MPI launcher started this process (its environment says so) and the
// build has MPI; otherwise this is a job of one. Call once, before any other thread starts.
Status joinCluster();
// Leaves the job (nothing for a job of one). Call once, last: with a failure (`exitCode` not 0)
// that the other ranks do not know of (not one agreeAcrossRanks returned), the whole job is
// aborted, since they would wait for this rank forever.
void leaveCluster(int exitCode = 0);

int clusterRank();  // 0 for a job of one
// Whether a wait for the other ranks was given up (agreeAcrossRanks): each survivor then says
// what it knows, since the rank that speaks for the job may be the one that died.
bool clusterAbandoned();
// Whether agreeAcrossRanks returned a failure: every rank knows of it, rank 0 says it.
bool clusterFailureAgreed();
int clusterSize();  // 1 for a job of one
inline bool clustered() {
  return clusterSize() > 1;
}
// Whether this build can join a job of several (built with MPI).
bool clusterSupported();

// Every rank's outcome of a step, known to all: ok when each succeeded, otherwise the failure
// of the lowest failed rank with the rank named ("rank 2: …") and its kind. Waits without
// spinning, so ranks that share a machine leave its cores to the ranks still working. Stopped
// while waiting (mpirun's SIGTERM when another rank died, or Ctrl-C), it fails as cancelled with
// the other ranks' last activities, and the job is left without waiting for them.
Status agreeAcrossRanks(const Status& mine);

// The sum of every rank's `mine`, known to all (as agreeAcrossRanks waits).
Result<std::uint64_t> sumAcrossRanks(std::uint64_t mine);

// Every rank's `mine`, concatenated in rank order, known to all (lengths may differ).
Result<std::vector<std::uint64_t>> gatherAcrossRanks(std::span<const std::uint64_t> mine);

// What this rank is doing, kept from now on in `directory`/rank-<r> (a directory every rank sees),
// so that when a rank dies the others can say what it was doing.
void setActivityDirectory(std::string directory);
void reportActivity(std::string_view what);
// The other ranks' last reported activities, a line each ("rank 1 (host, pid 12): building …").
std::string otherRanksActivities();

// A warning for a process that srun started as one of several tasks with no MPI plugin to join
// them (`srun --mpi=none`, or a site's default without PMIx): each task works alone, as tasks
// started on purpose for separate inputs do, but tasks meant as one job would each do the whole
// work. `stepTasks`: SLURM_STEP_NUM_TASKS (null: not set, as in a batch script). Nothing for a
// step of one task, or a process that joined a job.
std::optional<std::string> tasksNotJoined(const char* stepTasks);

// What mpirun tells a rank before MPI starts (null: not set), and whether OpenMPI's parameter
// files (the system's, the user's) choose a point-to-point layer.
struct LaunchEnvironment {
  const char* worldSize;   // OMPI_COMM_WORLD_SIZE
  const char* localSize;   // OMPI_COMM_WORLD_LOCAL_SIZE: the ranks on this machine
  const char* pml;         // OMPI_MCA_pml (mpirun --mca pml …, or -x)
  const char* paramFiles;  // OMPI_MCA_mca_base_param_files
  bool pmlInParamFile;
};
// Whether joinCluster asks OpenMPI for its shared-memory layer, ob1: every rank on this machine,
// which talks through shared memory whatever the layer, and no layer chosen anywhere. OpenMPI's
// own choice among its layers took 0.25 s of every job here (MPI_Init 0.27 s against 0.06 s).
// Every rank of one machine sees the same, so they all choose alike.
bool ob1SharedMemoryWanted(const LaunchEnvironment& launch);
// Whether an OpenMPI parameter file (`mca-params.conf`) chooses the point-to-point layer: a line
// `pml = NAME`. A list of layers not to use (`pml = ^ucx`, as Debian's own file has) chooses
// none; a missing file neither.
bool paramFileChoosesPml(const std::string& path);

// How many `units` ("faces", "nodes") of its share this rank has done, kept beside its activity
// (a small file written whole, at most ten times a second and at the first report of a stage;
// one held back is written by the next report or before the ranks next meet: agreeAcrossRanks,
// sumAcrossRanks, gatherAcrossRanks). What the file says may lag by the unit of work after a
// held-back report. Call it per piece of work, however small.
void reportProgress(std::string_view units, std::uint64_t done);

// Rank 0's progress bar for the whole job while it lives: the sum of every rank's last
// reportProgress in `units`, read from the activity directory twice a second. Nothing on other
// ranks.
class JobProgress {
 public:
  JobProgress(std::string label, std::string units, std::uint64_t total);
  ~JobProgress();
  JobProgress(const JobProgress&) = delete;
  JobProgress& operator=(const JobProgress&) = delete;

 private:
  std::mutex mutex_;
  std::condition_variable wake_;  // the destructor's: stop at once, not at the next poll
  bool stop_ = false;
  std::thread thread_;
};

// What this rank read and wrote in a stage (/proc/self/io's rchar and wchar since the last
// stage: what it asked of the file systems, from the page cache or not) and its peak memory,
// kept beside its activity for rank 0's report.
void recordStage(std::string_view stage);
// Every rank's recorded stages, a line each ("rank 1: chunks read 1.2 GiB, wrote …").
std::vector<std::string> rankStages();

// Items dealt out to `ranks` by their `work`, largest first, each to the least loaded rank so far
// (longest processing time first: within 4/3 of the best busiest rank); ties by item order, so
// every rank computes the same deal. The rank of each item.
std::vector<int> dealLargestFirst(std::span<const std::uint64_t> work, int ranks);

// Whether this rank is the first of the job to claim `path`, a file created exclusively on the
// file system every rank shares (work the ranks take in turn, whoever is free first); always, and
// no file, in a job of one. Claims are the caller's to remove before a job claims the same work
// again.
Result<bool> claimInJob(const std::string& path);

// A name for this rank in messages: "rank 2 of 4 (host, pid 1234)".
std::string describeRank();

}  // namespace lodforge
