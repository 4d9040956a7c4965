#include "lodforge/surface/reconstruct_ranks.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <filesystem>
#include <numeric>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/cluster.h"
#include "lodforge/core/directory.h"
#include "lodforge/core/progress.h"
#include "lodforge/surface/reconstruct_steps.h"
#include "lodforge/surface/resume_state.h"

namespace lodforge {

namespace {

// The claims of an earlier job's ranks on its runs (claimInJob), removed before a job's ranks
// claim them again.
Status forgetClaims(const std::string& workDirectory) {
  return removeFilesIn(workDirectory,
                       [](const std::string& name) { return name.ends_with(".claim"); });
}

// A job's runs: the state, and which runs an interrupted job finished (their pieces kept, taken
// when resuming), as rank 0 found them.
struct JobRuns {
  ReconstructState state;
  std::vector<char> kept;
};

// Rank 0: the runs whose pieces an interrupted job kept, when resuming.
std::vector<std::uint64_t> keptRuns(const ChunkRuns& runs, const std::string& workDirectory,
                                    const ReconstructOptions& options) {
  std::vector<std::uint64_t> kept;
  std::error_code error;
  for (std::size_t r = 0; r < runs.runCount() && options.resume; ++r)
    if (std::filesystem::exists(piecesPath(workDirectory, r), error)) kept.push_back(r);
  return kept;
}

// Where rank 0 of a job leaves the lattice and the runs for the others while they estimate
// normals (the runs' own state comes after).
std::string sortingStatePath(const std::string& workDirectory) {
  return workDirectory + "/sorting.json";
}

Error unreadableOnRank(const std::string& workDirectory) {
  return Error{ErrorKind::kIo,
               fmt::format("{}: cannot read the runs rank 0 sorted (is {} on a file system every "
                           "rank shares, and the input the same file for each?)",
                           describeRank(), workDirectory)};
}

// What rank 0 of a job saved in `path` for the others.
Result<ReconstructState> savedByLead(const std::string& path, const std::string& input,
                                     const std::string& workDirectory,
                                     const ReconstructOptions& options) {
  std::optional<ReconstructState> saved =
      loadReconstructState(path, reconstructIdentity(input, options));
  if (!saved) return unreadableOnRank(workDirectory);
  return std::move(*saved);
}

// Rank 0's first part of a job's sorting: the earlier job's claims cleared; its state when
// resuming, else the points sorted as far as their normals (the lattice and runs saved for the
// others when the ranks are to estimate the normals).
Status beginSorting(const std::string& input, const std::string& workDirectory,
                    const ReconstructOptions& options, std::optional<ReconstructState>& resumed,
                    std::optional<Sorting>& sorting) {
  LODFORGE_TRY(forgetClaims(workDirectory));
  resumed = resumedState(input, workDirectory, options);
  if (resumed) return {};
  LODFORGE_TRY(forgetEarlierRuns(workDirectory));
  Result<Sorting> planned = planSorting(input, workDirectory, options);
  if (!planned) return planned.status();
  sorting = std::move(*planned);
  if (!sorting->normalsByRun) return {};
  return saveReconstructState(sortingStatePath(workDirectory), reconstructIdentity(input, options),
                              stateOf(*sorting));
}

// The ranks' normals, run by run, each run claimed by the first rank free.
Status normalsShare(const ReconstructState& plan, const ReconstructOptions& options,
                    const std::string& workDirectory) {
  const ChunkRuns& runs = plan.runs;
  std::uint64_t made = 0;
  for (std::size_t r = 0; r < runs.runCount(); ++r) {
    Result<bool> claimed = claimInJob(fmt::format("{}/normals-{}.claim", workDirectory, r));
    if (!claimed) return claimed.status();
    if (!*claimed) continue;
    std::vector<OwnedNormalFile> files;
    LODFORGE_TRY(runNormals(plan.layout, runs, r, plan.runBudget, options, workDirectory, files));
    reportProgress("runs", ++made);
  }
  return {};
}

// Rank 0, once the ranks' normals are written: every run's merged into the record file.
Status mergeRunNormals(const Sorting& sorting, const std::string& workDirectory) {
  std::vector<OwnedNormalFile> files;
  for (std::size_t r = 0; r < sorting.runs.runCount(); ++r) {
    Result<std::vector<OwnedNormalFile>> run =
        runNormalFiles(sorting.layout, sorting.runs, r, sorting.budget, workDirectory);
    if (!run) return run.status();
    files.insert(files.end(), run->begin(), run->end());
  }
  return mergeNormals(sorting.cloudPath, files);
}

// A job's normals estimated run by run: the ranks take the runs, rank 0 merges them. Every
// failure is agreed.
Status normalsTogether(const std::string& input, const std::string& workDirectory,
                       const ReconstructOptions& options, const std::optional<Sorting>& sorting) {
  const bool lead = clusterRank() == 0;
  Result<ReconstructState> plan =
      lead ? stateOf(*sorting)
           : savedByLead(sortingStatePath(workDirectory), input, workDirectory, options);
  LODFORGE_TRY(agreeAcrossRanks(plan.status()));
  reportActivity(fmt::format("estimating the normals of runs, {} in all", plan->runs.runCount()));
  {
    // Until every rank is done: the bar counts the runs of all.
    const JobProgress progress(fmt::format("reconstruct: normals, {} ranks", clusterSize()), "runs",
                               plan->runs.runCount());
    LODFORGE_TRY(agreeAcrossRanks(normalsShare(*plan, options, workDirectory)));
  }
  return agreeAcrossRanks(lead ? mergeRunNormals(*sorting, workDirectory) : Status{});
}

// Rank 0's last part: the runs' files written and the state saved for the others (or an
// interrupted job's state).
Result<ReconstructState> finishOnLead(const std::string& input, const std::string& workDirectory,
                                      const ReconstructOptions& options,
                                      std::optional<ReconstructState>& resumed,
                                      const std::optional<Sorting>& sorting) {
  if (resumed) return std::move(*resumed);
  Result<ReconstructState> state = finishSorting(*sorting, workDirectory, options);
  if (!state) return state.status();
  std::error_code ignored;
  std::filesystem::remove(sortingStatePath(workDirectory), ignored);
  LODFORGE_TRY(saveReconstructState(reconstructStatePath(workDirectory),
                                    reconstructIdentity(input, options), *state));
  return state;
}

// Sorted by rank 0 (the normals estimated by the ranks), or an interrupted job's state taken,
// then read by the other ranks, each checking that its chunks in flight fit its memory limit;
// rank 0's list of the kept runs given to all before any run is made.
Result<JobRuns> stateOnEveryRank(const std::string& input, const std::string& workDirectory,
                                 const ReconstructOptions& options) {
  const bool lead = clusterRank() == 0;
  reportActivity(lead ? "sorting the points into runs"
                      : "waiting for rank 0 to sort the points into runs");
  std::optional<ReconstructState> resumed;
  std::optional<Sorting> sorting;
  LODFORGE_TRY(agreeAcrossRanks(lead ? beginSorting(input, workDirectory, options, resumed, sorting)
                                     : Status{}));
  Result<std::uint64_t> byRun = sumAcrossRanks(sorting && sorting->normalsByRun ? 1 : 0);
  if (!byRun) return byRun.status();
  if (*byRun > 0) LODFORGE_TRY(normalsTogether(input, workDirectory, options, sorting));
  Result<ReconstructState> state =
      lead ? finishOnLead(input, workDirectory, options, resumed, sorting)
           : Result<ReconstructState>(Error{ErrorKind::kInternal, "not read yet"});
  LODFORGE_TRY(agreeAcrossRanks(lead ? state.status() : Status{}));
  if (!lead)
    state = savedByLead(reconstructStatePath(workDirectory), input, workDirectory, options);
  if (!lead && state) {
    const Status fits = checkChunkFits(state->layout, options, input);
    if (!fits.ok()) state = fits.error();
  }
  LODFORGE_TRY(agreeAcrossRanks(state.status()));
  Result<std::vector<std::uint64_t>> kept = gatherAcrossRanks(
      lead ? keptRuns(state->runs, workDirectory, options) : std::vector<std::uint64_t>{});
  if (!kept) return kept.status();
  std::vector<char> flags(state->runs.runCount(), 0);
  for (const std::uint64_t r : *kept) flags.at(static_cast<std::size_t>(r)) = 1;
  return JobRuns{std::move(*state), std::move(flags)};
}

// A job's runs, claimed by the ranks one at a time, the largest (by points, overlaps included)
// first, each made into its pieces file by the rank that claimed it: a rank that is done early
// takes more, whatever a run's cost. Returns the chunks this rank made.
Result<std::uint64_t> makeShare(const JobRuns& job, const std::string& workDirectory,
                                const ReconstructOptions& options, ReconstructStats& stats) {
  const ChunkRuns& runs = job.state.runs;
  std::vector<std::uint64_t> work(runs.runCount());
  for (std::size_t r = 0; r < work.size(); ++r)
    for (std::size_t c = runs.firstChunk[r]; c < runs.firstChunk[r + 1]; ++c)
      work[r] += runs.points[c] + 1;
  std::vector<std::size_t> order(work.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return work[a] > work[b]; });
  Progress mine("", runs.chunks.size());  // this rank's part, shown by rank 0's JobProgress
  std::uint64_t made = 0;
  std::error_code error;
  for (const std::size_t r : order) {
    if (job.kept[r] != 0) continue;
    Result<bool> claimed = claimInJob(fmt::format("{}/run-{}.claim", workDirectory, r));
    if (!claimed) return claimed.status();
    if (!*claimed) continue;
    Result<PieceWriter> writer = PieceWriter::create(piecesPath(workDirectory, r));
    if (!writer) return writer.status();
    KeptPieces tee(nullptr, &*writer);
    LODFORGE_TRY(makeRun(job.state, r, workDirectory, options, tee, mine, stats));
    LODFORGE_TRY(writer->finish());
    checkpointReached("run");
    std::filesystem::remove(runPath(workDirectory, r), error);
    made += runs.firstChunk[r + 1] - runs.firstChunk[r];
    reportProgress("chunks", made);
  }
  return made;
}

// Rank 0, once every run is made: their pieces into the sink, in chunk order.
Status joinRuns(const ReconstructState& state, const std::string& workDirectory, PieceSink& sink) {
  LODFORGE_TRY(sink.begin(state.layout, state.hasColors));
  Progress progress("reconstruct: joining the runs", state.runs.runCount());
  for (std::size_t r = 0; r < state.runs.runCount(); ++r) {
    LODFORGE_TRY(replayPieces(piecesPath(workDirectory, r), sink));
    progress.advance(1);
  }
  progress.finish();
  return {};
}

}  // namespace

Result<ReconstructStats> reconstructAcrossRanks(const std::string& input,
                                                const std::string& workDirectory,
                                                const ReconstructOptions& options,
                                                PieceSink& sink) {
  const auto start = std::chrono::steady_clock::now();
  const auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  Result<JobRuns> job = stateOnEveryRank(input, workDirectory, options);
  if (!job) return job.status();
  const ReconstructState& state = job->state;
  ReconstructStats stats = statsOf(state);
  stats.sortedSeconds = seconds();
  stats.resumedRuns = static_cast<std::uint64_t>(std::count(job->kept.begin(), job->kept.end(), 1));
  recordStage("sorting");
  reportActivity(fmt::format("making runs of chunks, {} in all", state.runs.runCount()));
  Result<std::uint64_t> made = std::uint64_t{0};
  double done = 0;
  {
    // Until every rank is done: the bar counts the chunks of all.
    const JobProgress progress(fmt::format("reconstruct: chunks, {} ranks", clusterSize()),
                               "chunks", state.runs.chunks.size());
    made = makeShare(*job, workDirectory, options, stats);
    done = seconds();
    LODFORGE_TRY(agreeAcrossRanks(made.status()));
  }
  const std::array<std::uint64_t, 3> mine{*made, stats.streamedChunks,
                                          std::bit_cast<std::uint64_t>(done)};
  Result<std::vector<std::uint64_t>> all = gatherAcrossRanks(mine);
  if (!all) return all.status();
  stats.streamedChunks = 0;
  for (std::size_t i = 0; i + 2 < all->size(); i += 3) {
    stats.rankChunks.push_back((*all)[i]);
    stats.streamedChunks += (*all)[i + 1];
    stats.rankMadeSeconds.push_back(std::bit_cast<double>((*all)[i + 2]));
  }
  stats.madeSeconds = seconds();
  recordStage("runs");
  const bool lead = clusterRank() == 0;
  reportActivity(lead ? "joining the runs" : "waiting for rank 0 to join the runs");
  const Status joined = lead ? joinRuns(state, workDirectory, sink) : Status{};
  recordStage("join");
  LODFORGE_TRY(agreeAcrossRanks(joined));
  stats.joinedSeconds = seconds();
  if (lead) stats.rankStages = rankStages();
  return stats;
}

}  // namespace lodforge
