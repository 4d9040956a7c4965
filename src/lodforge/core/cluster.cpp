#include "lodforge/core/cluster.h"

#include <numeric>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <string_view>
#include <thread>
#include <vector>

#include <filesystem>
#include <fstream>
#include <mutex>

#if LODFORGE_WITH_MPI
#include <mpi.h>
#endif

#include "lodforge/core/file.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"

namespace lodforge {
namespace {

constexpr bool kWithMpi = LODFORGE_WITH_MPI != 0;

int rank = 0, size = 1;
bool joined = false;
bool abandoned = false;      // a wait was interrupted: the others may be gone, do not finalize
bool failureAgreed = false;  // every rank knows of the failure agreeAcrossRanks returned
std::string activityDirectory;
std::array<std::uint64_t, 2> ioAtLastStage{};  // recordStage's /proc/self/io at the last stage
std::string stagesRecorded;

std::string activityPath(int of) {
  return fmt::format("{}/rank-{}", activityDirectory, of);
}
std::string progressPath(int of) {
  return fmt::format("{}/done-{}", activityDirectory, of);
}
std::mutex progressMutex;  // reports come from the worker threads
// This rank's last report and whether its file says it yet (under progressMutex).
struct ProgressReport {
  std::string units;
  std::uint64_t done = 0;
  bool written = true;
  std::chrono::steady_clock::time_point writtenAt{};
};
ProgressReport progressReport;

void writeProgressReport() {
  // Best effort, like the activity: a report that cannot be written must not stop the work.
  (void)OutputFile::writeWhole(progressPath(rank),
                               fmt::format("{} {}", progressReport.done, progressReport.units));
  progressReport.written = true;
  progressReport.writtenAt = std::chrono::steady_clock::now();
}

// What reportProgress held back, written before the ranks meet: a stage's bar, read by rank 0
// once they have, then ends at the job's total.
void flushProgress() {
  const std::lock_guard lock(progressMutex);
  if (!progressReport.written && !activityDirectory.empty()) writeProgressReport();
}

// A rank's last reported progress: how many of what ("12 nodes"; empty: none).
std::pair<std::uint64_t, std::string> lastProgress(int of) {
  Result<std::string> text = readFileToString(progressPath(of), 128);
  if (!text) return {0, ""};
  char* end = nullptr;
  const std::uint64_t done = std::strtoull(text->c_str(), &end, 10);
  return {done, std::string(end + (*end == ' ' ? 1 : 0))};
}

// The sum of every rank's last reported progress in `units` (a rank still at another stage: 0).
std::uint64_t jobDone(std::string_view units) {
  std::uint64_t sum = 0;
  for (int r = 0; r < size; ++r) {
    const auto [done, of] = lastProgress(r);
    if (of == units) sum += done;
  }
  return sum;
}

// Set by mpirun (OpenMPI's, PMIx) and srun (PMI-2, PMIx): the process belongs to a job.
bool launchedAsJob() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

#if LODFORGE_WITH_MPI
Status mpiFailed(const char* what, int code) {
  std::array<char, MPI_MAX_ERROR_STRING> text{};
  int length = 0;
  MPI_Error_string(code, text.data(), &length);
  return Error{ErrorKind::kIo,
               fmt::format("MPI: {}: {}", what,
                           std::string_view(text.data(), static_cast<std::size_t>(length)))};
}

// Polls instead of blocking: OpenMPI's blocking waits spin a core, which ranks sharing a machine
// need for their own work while one of them chunks alone.
Status waitQuietly(MPI_Request& request) {
  int done = 0;
  while (done == 0) {
    if (const int code = MPI_Test(&request, &done, MPI_STATUS_IGNORE); code != MPI_SUCCESS) {
      abandoned = true;
      return mpiFailed("waiting for the other ranks", code);
    }
    if (done != 0) break;
    if (cancelRequested()) {
      abandoned = true;
      return Error{ErrorKind::kCancelled,
                   fmt::format("{} stopped while waiting for the other ranks{}", describeRank(),
                               otherRanksActivities())};
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return {};
}

#endif

}  // namespace

bool clusterSupported() {
  return LODFORGE_WITH_MPI != 0;
}

bool ob1SharedMemoryWanted(const LaunchEnvironment& launch) {
  if (launch.worldSize == nullptr || launch.localSize == nullptr) return false;
  if (std::string_view(launch.worldSize) != launch.localSize) return false;
  return launch.pml == nullptr && launch.paramFiles == nullptr && !launch.pmlInParamFile;
}

bool paramFileChoosesPml(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t at = line.find_first_not_of(" \t");
    if (at == std::string::npos || line.compare(at, 3, "pml") != 0) continue;
    const std::size_t equals = line.find_first_not_of(" \t", at + 3);
    if (equals == std::string::npos || line[equals] != '=') continue;
    const std::size_t value = line.find_first_not_of(" \t", equals + 1);
    if (value != std::string::npos && line[value] != '^') return true;
  }
  return false;
}

#if LODFORGE_WITH_MPI
namespace {

// Asks OpenMPI for its shared-memory layer where ob1SharedMemoryWanted says so.
void preferSharedMemoryOnOneMachine() {
  const char* home = std::getenv("HOME");
  const bool inFile =
      paramFileChoosesPml("/etc/openmpi/openmpi-mca-params.conf") ||
      (home != nullptr && paramFileChoosesPml(std::string(home) + "/.openmpi/mca-params.conf"));
  const LaunchEnvironment launch{
      std::getenv("OMPI_COMM_WORLD_SIZE"), std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE"),
      std::getenv("OMPI_MCA_pml"), std::getenv("OMPI_MCA_mca_base_param_files"), inFile};
  if (ob1SharedMemoryWanted(launch)) ::setenv("OMPI_MCA_pml", "ob1", 0);
}

}  // namespace
#endif

std::optional<std::string> tasksNotJoined(const char* stepTasks) {
  if (joined || stepTasks == nullptr || std::strtoll(stepTasks, nullptr, 10) <= 1)
    return std::nullopt;
  return fmt::format(
      "started by srun as one of {} tasks with no MPI plugin to join them: each "
      "task works alone{}",
      stepTasks,
      kWithMpi ? " (`srun --mpi=pmix` makes them one job, docs/distributed.md)"
               : " (this lodforge was built without MPI)");
}

Status joinCluster() {
  assert(!joined);
  if (!launchedAsJob()) return {};
#if LODFORGE_WITH_MPI
  preferSharedMemoryOnOneMachine();
  int provided = 0;
  // Only the main thread talks to the other ranks; the pipelines' worker threads never do.
  const int code = MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  if (code != MPI_SUCCESS) return mpiFailed("cannot join the job", code);
  joined = true;
  // Errors come back as codes (mpiFailed), not as the job ended by MPI itself.
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return {};
#else
  return Error{ErrorKind::kUsage,
               "started by an MPI launcher, but this lodforge was built without MPI "
               "(LODFORGE_MPI=OFF): it would run the whole job once per rank"};
#endif
}

void leaveCluster(int exitCode) {
#if LODFORGE_WITH_MPI
  // A failure the other ranks do not know of: they would wait for this one forever (and
  // MPI_Finalize for them), so the job ends here.
  if (joined && exitCode != 0 && !failureAgreed && !abandoned && size > 1)
    MPI_Abort(MPI_COMM_WORLD, exitCode);
  if (joined && !abandoned) MPI_Finalize();
#endif
  joined = false;
  abandoned = false;
  failureAgreed = false;
  activityDirectory.clear();
  stagesRecorded.clear();
  ioAtLastStage = {};
  rank = 0;
  size = 1;
}

int clusterRank() {
  return rank;
}
bool clusterAbandoned() {
  return abandoned;
}

bool clusterFailureAgreed() {
  return failureAgreed;
}
int clusterSize() {
  return size;
}

Result<bool> claimInJob(const std::string& path) {
  if (!clustered()) return true;  // a job of one has no one to share with
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd >= 0) {
    ::close(fd);
    return true;
  }
  if (errno == EEXIST) return false;
  return ioErrorFromErrno(path, "claim");
}

std::string describeRank() {
  std::array<char, 256> host{};
  if (gethostname(host.data(), host.size() - 1) != 0) host[0] = '\0';
  return fmt::format("rank {} of {} ({}, pid {})", rank, size, host.data(), getpid());
}

void setActivityDirectory(std::string directory) {
  activityDirectory = std::move(directory);
  std::error_code ignored;
  if (!clustered()) return;
  std::filesystem::create_directories(activityDirectory, ignored);
  // What this rank of an interrupted job said is not what this one does.
  for (const std::string& path : {activityPath(rank), progressPath(rank),
                                  fmt::format("{}/stages-{}", activityDirectory, rank)})
    std::filesystem::remove(path, ignored);
  const std::lock_guard lock(progressMutex);
  progressReport = {};
}

void reportActivity(std::string_view what) {
  if (!clustered() || activityDirectory.empty()) return;
  // Best effort: a report that cannot be written must not stop the work.
  (void)OutputFile::writeWhole(activityPath(rank), fmt::format("{}: {}", describeRank(), what));
}

void reportProgress(std::string_view units, std::uint64_t done) {
  if (!clustered() || activityDirectory.empty()) return;
  const std::lock_guard lock(progressMutex);
  const bool newStage = units != progressReport.units;
  progressReport.units = units;
  // Worker threads count in turn but may take the lock out of turn: a count never goes back.
  progressReport.done = newStage ? done : std::max(progressReport.done, done);
  progressReport.written = false;
  // A report replaces the file by a rename, which ext4 makes write the new file out at once: one
  // per tile cost a 20 M-point job a second. Rank 0 reads twice a second; ten a second are plenty.
  if (newStage ||
      std::chrono::steady_clock::now() - progressReport.writtenAt >= std::chrono::milliseconds(100))
    writeProgressReport();
}

JobProgress::JobProgress(std::string label, std::string units, std::uint64_t total) {
  if (!clustered() || rank != 0) return;
  thread_ = std::thread([this, label = std::move(label), units = std::move(units), total] {
    Progress progress(label, total);
    std::uint64_t shown = 0;
    std::unique_lock lock(mutex_);
    while (true) {
      const bool stopping = stop_;
      const std::uint64_t done = jobDone(units);
      if (done > shown) progress.advance(done - shown);
      shown = std::max(shown, done);
      if (stopping) break;
      wake_.wait_for(lock, std::chrono::milliseconds(500), [this] { return stop_; });
    }
  });
}

JobProgress::~JobProgress() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

namespace {

// /proc/self/io's rchar and wchar (0 where the file is missing).
std::array<std::uint64_t, 2> processIo() {
  std::array<std::uint64_t, 2> io{};
  std::ifstream in("/proc/self/io");  // a /proc file tells no size: read as a stream
  std::string key;
  std::uint64_t value = 0;
  while (in >> key >> value) {
    if (key == "rchar:") io[0] = value;
    if (key == "wchar:") io[1] = value;
  }
  return io;
}

}  // namespace

void recordStage(std::string_view stage) {
  if (!clustered() || activityDirectory.empty()) return;
  const std::array<std::uint64_t, 2> now = processIo();
  stagesRecorded +=
      fmt::format("{} read {}, wrote {}; ", stage, formatBytes(now[0] - ioAtLastStage[0]),
                  formatBytes(now[1] - ioAtLastStage[1]));
  ioAtLastStage = now;
  (void)OutputFile::writeWhole(
      fmt::format("{}/stages-{}", activityDirectory, rank),
      fmt::format("rank {}: {}peak memory {}", rank, stagesRecorded, formatBytes(peakRssBytes())));
}

std::vector<std::string> rankStages() {
  std::vector<std::string> lines;
  for (int r = 0; r < size && !activityDirectory.empty(); ++r) {
    Result<std::string> text =
        readFileToString(fmt::format("{}/stages-{}", activityDirectory, r), 4096);
    if (text) lines.push_back(*text);
  }
  return lines;
}

std::string otherRanksActivities() {
  std::string lines;
  if (activityDirectory.empty()) return lines;
  for (int r = 0; r < size; ++r) {
    if (r == rank) continue;
    Result<std::string> text = readFileToString(activityPath(r), 4096);
    const auto [done, units] = lastProgress(r);
    lines += fmt::format("\n  {}{}", text ? *text : fmt::format("rank {}: nothing reported", r),
                         units.empty() ? "" : fmt::format("; {} {} done", done, units));
  }
  return lines.empty() ? lines : "; their last steps:" + lines;
}

Result<std::uint64_t> sumAcrossRanks(std::uint64_t mine) {
  if (!clustered()) return mine;
  flushProgress();
#if LODFORGE_WITH_MPI
  std::uint64_t sum = 0;
  MPI_Request request;
  const int code = MPI_Iallreduce(&mine, &sum, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD, &request);
  if (code != MPI_SUCCESS) return mpiFailed("cannot add up the ranks' counts", code);
  LODFORGE_TRY(waitQuietly(request));
  return sum;
#else
  return mine;
#endif
}

Result<std::vector<std::uint64_t>> gatherAcrossRanks(std::span<const std::uint64_t> mine) {
  if (!clustered()) return std::vector<std::uint64_t>(mine.begin(), mine.end());
  flushProgress();
#if LODFORGE_WITH_MPI
  const auto ranks = static_cast<std::size_t>(size);
  const int own = static_cast<int>(mine.size());
  std::vector<int> lengths(ranks), offsets(ranks);
  MPI_Request request;
  int code = MPI_Iallgather(&own, 1, MPI_INT, lengths.data(), 1, MPI_INT, MPI_COMM_WORLD, &request);
  if (code != MPI_SUCCESS) return mpiFailed("cannot gather the ranks' counts", code);
  LODFORGE_TRY(waitQuietly(request));
  int total = 0;
  for (std::size_t r = 0; r < ranks; ++r) offsets[r] = total, total += lengths[r];
  std::vector<std::uint64_t> all(static_cast<std::size_t>(total));
  code = MPI_Iallgatherv(mine.data(), own, MPI_UINT64_T, all.data(), lengths.data(), offsets.data(),
                         MPI_UINT64_T, MPI_COMM_WORLD, &request);
  if (code != MPI_SUCCESS) return mpiFailed("cannot gather the ranks' values", code);
  LODFORGE_TRY(waitQuietly(request));
  return all;
#else
  return std::vector<std::uint64_t>(mine.begin(), mine.end());
#endif
}

Status agreeAcrossRanks(const Status& mine) {
  if (!clustered()) return mine;
  flushProgress();
  failureAgreed = false;  // only the last step's: a job may go on after an agreed fallback
#if LODFORGE_WITH_MPI
  // Each rank's kind (-1: ok) and message length, then the messages.
  const std::string message = mine.ok() ? "" : mine.message();
  const std::array<int, 2> own{mine.ok() ? -1 : static_cast<int>(mine.kind()),
                               static_cast<int>(message.size())};
  const auto ranks = static_cast<std::size_t>(size);
  std::vector<int> all(2 * ranks);
  MPI_Request request;
  int code =
      MPI_Iallgather(own.data(), 2, MPI_INT, all.data(), 2, MPI_INT, MPI_COMM_WORLD, &request);
  if (code != MPI_SUCCESS) return mpiFailed("cannot exchange the ranks' outcomes", code);
  LODFORGE_TRY(waitQuietly(request));
  std::vector<int> lengths(ranks), offsets(ranks);
  int total = 0;
  for (std::size_t r = 0; r < ranks; ++r) {
    lengths[r] = all[2 * r + 1];
    offsets[r] = total;
    total += lengths[r];
  }
  std::string messages(static_cast<std::size_t>(total), '\0');
  code = MPI_Iallgatherv(message.data(), own[1], MPI_CHAR, messages.data(), lengths.data(),
                         offsets.data(), MPI_CHAR, MPI_COMM_WORLD, &request);
  if (code != MPI_SUCCESS) return mpiFailed("cannot exchange the ranks' outcomes", code);
  LODFORGE_TRY(waitQuietly(request));
  for (std::size_t r = 0; r < ranks; ++r) {
    if (all[2 * r] < 0) continue;
    failureAgreed = true;
    if (static_cast<int>(r) == rank) return mine;  // our own, as a job of one would say it
    const std::string text =
        messages.substr(static_cast<std::size_t>(offsets[r]), static_cast<std::size_t>(lengths[r]));
    return Error{static_cast<ErrorKind>(all[2 * r]), fmt::format("rank {}: {}", r, text)};
  }
  return {};
#else
  return mine;
#endif
}

std::vector<int> dealLargestFirst(std::span<const std::uint64_t> work, int ranks) {
  std::vector<std::size_t> order(work.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return work[a] > work[b]; });
  std::vector<std::uint64_t> load(static_cast<std::size_t>(ranks), 0);
  std::vector<int> owner(work.size(), 0);
  for (const std::size_t i : order) {
    const auto least =
        static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    owner[i] = static_cast<int>(least);
    load[least] += work[i];
  }
  return owner;
}

}  // namespace lodforge
