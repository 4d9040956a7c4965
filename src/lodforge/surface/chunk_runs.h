// Out of core, the chunks are worked in runs: consecutive chunks (in chunk order) whose points,
// overlap included, fit a budget. One pass counts each chunk's points, the runs are cut from the
// counts, and a second pass writes each run a file of the records it needs, in input order (the
// order every sum follows). A run is then read whole, its chunks made, and freed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/surface/cloud_file.h"
#include "lodforge/surface/layout.h"

namespace lodforge {

struct ChunkRuns {
  std::vector<std::uint64_t> chunks;    // the chunks any point reaches, ascending
  std::vector<std::uint64_t> points;    // per chunk: the points it holds, overlap included
  std::vector<std::size_t> firstChunk;  // per run: its first entry in `chunks`; then the end
  std::size_t runCount() const { return firstChunk.empty() ? 0 : firstChunk.size() - 1; }
  // The run holding chunk `c` (one of `chunks`).
  std::size_t runOf(std::uint64_t c) const;
};

// Counts the chunks' points in the record file and cuts runs of at most `runPoints` points (a
// chunk with more is a run of its own).
Result<ChunkRuns> planRuns(const std::string& cloudPath, const ChunkLayout& layout, double radius,
                           std::uint64_t runPoints);

// The file of run r in `directory`.
std::string runPath(const std::string& directory, std::size_t run);

// Writes each run's records (every point reaching one of its chunks) to runPath(directory, r).
Status writeRuns(const std::string& cloudPath, const ChunkLayout& layout, double radius,
                 const ChunkRuns& runs, const std::string& directory);

}  // namespace lodforge
