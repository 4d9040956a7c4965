// The steps of an out-of-core reconstruction (surface/reconstruct.h) that one process and the
// ranks of a job (surface/reconstruct_ranks.h) take alike: a run's memory budget, the points
// sorted into runs with their normals, a run's chunks made.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "lodforge/core/progress.h"
#include "lodforge/core/status.h"
#include "lodforge/surface/chunk_runs.h"
#include "lodforge/surface/cloud_file.h"
#include "lodforge/surface/layout.h"
#include "lodforge/surface/mesh_join.h"
#include "lodforge/surface/reconstruct.h"
#include "lodforge/surface/resume_state.h"

namespace lodforge {

// A run of one chunk with more points than `budget`: streamed, not read whole. (The runs may
// have been cut with another budget, by an earlier run a resumed one takes.)
bool isDenseRun(const ChunkRuns& runs, std::size_t r, std::uint64_t budget);

// The chunks in flight (one a thread) within half of the memory limit, else kLimit with the
// least limit that would do.
Status checkChunkFits(const ChunkLayout& layout, const ReconstructOptions& options,
                      const std::string& name);

// The points a run may hold, overlaps included: options.runPoints, else what the memory limit
// leaves beside the grids in flight, else kDefaultRunPoints.
std::uint64_t runBudget(const ChunkLayout& layout, const ReconstructOptions& options);

// The options' lengths are in the cloud's units; `unitScale` makes them the frame's.
double voxelFor(const ReconstructOptions& options, double spacing, double unitScale);

// N, the voxels along a chunk's edge: options.chunkVoxels, or options.chunkLength over the voxel.
std::uint32_t chunkVoxelsFor(const ReconstructOptions& options, double voxel, double unitScale);

// The run's chunks made a few per thread at a time and handed on in chunk order.
Status makeChunks(const ChunkLayout& layout, std::span<const CloudRecord> records,
                  std::span<const std::uint64_t> chunks, const ReconstructOptions& options,
                  bool colors, PieceSink& sink, Progress& progress,
                  std::vector<SurfacePiece>* pieces);

// Run r's normals: each owned point's from its neighbours in the run (a run of one chunk denser
// than `budget`, the one the runs were cut with, in parts); the files of owned normals appended
// to `files`.
Status runNormals(const ChunkLayout& layout, const ChunkRuns& runs, std::size_t r,
                  std::uint64_t budget, const ReconstructOptions& options,
                  const std::string& directory, std::vector<OwnedNormalFile>& files);

// The files runNormals wrote for run r, their counts from their sizes (what a rank of a job wrote:
// mergeNormals then finds a normal missing from a file cut short).
Result<std::vector<OwnedNormalFile>> runNormalFiles(const ChunkLayout& layout,
                                                    const ChunkRuns& runs, std::size_t r,
                                                    std::uint64_t budget,
                                                    const std::string& directory);

// What the runs depend on: a resumed reconstruction takes earlier work only when this is
// unchanged (the memory budget is not in it: a chunk held or streamed makes the same bits).
nlohmann::json reconstructIdentity(const std::string& input, const ReconstructOptions& options);

// Removes an earlier reconstruction's state and pieces from the work directory (its run files
// are written again).
Status forgetEarlierRuns(const std::string& workDirectory);

// The points sorted as far as their normals: the input read into a record file, the lattice
// laid over it and the runs cut; normals turned by propagation are set, and for normals to be
// estimated run by run (`normalsByRun`) the run files are written.
struct Sorting {
  std::string cloudPath;
  CloudSummary cloud;
  ChunkLayout layout;
  ChunkRuns runs;
  std::uint64_t budget = 0;  // runBudget: what the runs were cut with, and dense chunks found by
  bool normalsByRun = false;
};

// Steps one process takes in turn (sortIntoRuns) and a job's ranks share (reconstruct_ranks):
// planned, the normals estimated run by run where `normalsByRun` (runNormals for each run, then
// mergeNormals), finished.
Result<Sorting> planSorting(const std::string& input, const std::string& workDirectory,
                            const ReconstructOptions& options);

// What the sorting makes, once finished: the state saved for --resume and for a job's ranks.
ReconstructState stateOf(const Sorting& sorting);

// The points, their normals set, written into the files of the runs; the record file goes.
Result<ReconstructState> finishSorting(const Sorting& sorting, const std::string& workDirectory,
                                       const ReconstructOptions& options);

// The input read into a record file, the lattice laid over it, normals estimated where missing,
// and the points written into the files of the runs of chunks.
Result<ReconstructState> sortIntoRuns(const std::string& input, const std::string& workDirectory,
                                      const ReconstructOptions& options);

// Passes each piece on (to no sink: a job's share of the runs) and keeps it in the run's
// pieces file.
class KeptPieces : public PieceSink {
 public:
  KeptPieces(PieceSink* sink, PieceWriter* writer) : sink_(sink), writer_(writer) {}
  Status begin(const ChunkLayout&, bool) override { return {}; }
  Status add(std::uint64_t chunk, const SurfacePiece& piece) override {
    if (writer_) LODFORGE_TRY(writer_->add(chunk, piece));
    return sink_ ? sink_->add(chunk, piece) : Status{};
  }

 private:
  PieceSink* sink_;
  PieceWriter* writer_;
};

// One run's chunks: held in memory, or a run's single chunk denser than a run may hold streamed
// from its file.
Status makeRun(const ReconstructState& state, std::size_t r, const std::string& workDirectory,
               const ReconstructOptions& options, PieceSink& sink, Progress& progress,
               ReconstructStats& stats);

// An interrupted reconstruction's state, when resuming and it matches. (Only work kept for
// resuming has its pieces: without them, the run files are gone.)
std::optional<ReconstructState> resumedState(const std::string& input,
                                             const std::string& workDirectory,
                                             const ReconstructOptions& options);

// The state the runs are made from: an interrupted reconstruction's when resuming and it
// matches, else the points sorted afresh (and the state saved when resumable).
Result<ReconstructState> stateOfRuns(const std::string& input, const std::string& workDirectory,
                                     const ReconstructOptions& options);

// The figures of a reconstruction made from `state` (its lattice, points and runs).
ReconstructStats statsOf(const ReconstructState& state);

}  // namespace lodforge
