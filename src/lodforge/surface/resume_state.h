// What lets `reconstruct --resume` go on from an interrupted reconstruction: once the points are
// sorted into runs, a state file (the input and options they were made from, the lattice, the
// runs); after each run, a file of its chunks' pieces. A resumed reconstruction replays the
// pieces of the runs that are done into its sink, in chunk order as before, so it writes the same
// bytes, and makes the other runs from their run files, which stay until their pieces are saved.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "lodforge/core/file.h"
#include "lodforge/core/status.h"
#include "lodforge/surface/chunk_runs.h"
#include "lodforge/surface/layout.h"
#include "lodforge/surface/mesh_join.h"

namespace lodforge {

struct ReconstructState {
  ChunkLayout layout;
  ChunkRuns runs;
  // The points a run held when the runs were cut: which chunks are dense, and so in how many
  // parts their normals were estimated (every rank of a job must take the same).
  std::uint64_t runBudget = 0;
  std::uint64_t points = 0;
  bool hasColors = false, estimatedNormals = false;
  double unitScale = 1;  // the frame's length of one of the cloud's units (CloudSummary)
  std::vector<std::string> warnings;  // the reading's (CloudSummary); not kept for --resume
};

// The state file in a reconstruction's work directory.
std::string reconstructStatePath(const std::string& workDirectory);
// Written whole and atomically, after the run files are complete.
Status saveReconstructState(const std::string& path, const nlohmann::json& identity,
                            const ReconstructState& state);
// The state of an earlier run when it is intact and its identity is `identity`.
std::optional<ReconstructState> loadReconstructState(const std::string& path,
                                                     const nlohmann::json& identity);

// The pieces of run r, present only when the run is done (written under a temporary name).
std::string piecesPath(const std::string& workDirectory, std::size_t run);

// Pieces appended as a run makes them; the file appears at finish().
class PieceWriter {
 public:
  static Result<PieceWriter> create(const std::string& path);
  Status add(std::uint64_t chunk, const SurfacePiece& piece);
  Status finish() { return file_.commit(); }

 private:
  explicit PieceWriter(OutputFile file) : file_(std::move(file)) {}
  OutputFile file_;
};

// Hands every piece of the file to `sink`, in the order they were written.
Status replayPieces(const std::string& path, PieceSink& sink);

}  // namespace lodforge
