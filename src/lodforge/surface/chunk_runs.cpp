#include "lodforge/surface/chunk_runs.h"

#include <algorithm>
#include <cassert>

#include <fmt/format.h>

#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"

namespace lodforge {

namespace {

// Counts are held for every chunk of the lattice: past this many the lattice is too fine for
// its chunk size.
constexpr std::uint64_t kMostChunks = std::uint64_t{1} << 24;

// Calls `each` for every chunk of the box.
template <class F>
void forEachChunk(const ChunkLayout& layout, const ChunkBox& box, F&& each) {
  for (std::uint64_t z = box.lo[2]; z <= box.hi[2]; ++z)
    for (std::uint64_t y = box.lo[1]; y <= box.hi[1]; ++y)
      for (std::uint64_t x = box.lo[0]; x <= box.hi[0]; ++x) each(layout.chunkIndex(x, y, z));
}

}  // namespace

std::size_t ChunkRuns::runOf(std::uint64_t c) const {
  assert(std::binary_search(chunks.begin(), chunks.end(), c));
  const auto entry =
      static_cast<std::size_t>(std::lower_bound(chunks.begin(), chunks.end(), c) - chunks.begin());
  return static_cast<std::size_t>(std::upper_bound(firstChunk.begin(), firstChunk.end(), entry) -
                                  firstChunk.begin() - 1);
}

Result<ChunkRuns> planRuns(const std::string& cloudPath, const ChunkLayout& layout, double radius,
                           std::uint64_t runPoints) {
  assert(radius >= 0);
  if (layout.chunkCount() > kMostChunks)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: {} chunks of {}³ voxels are too many to plan (at most {}): use "
                             "a larger --chunk-size or --voxel",
                             cloudPath, formatCount(layout.chunkCount()), layout.n,
                             formatCount(kMostChunks))};
  std::vector<std::uint64_t> counts(static_cast<std::size_t>(layout.chunkCount()), 0);
  LODFORGE_TRY(forEachRecordBlock(cloudPath, [&](std::span<const CloudRecord> block) {
    for (const CloudRecord& r : block)
      forEachChunk(layout, layout.reach(r.position, radius),
                   [&](std::uint64_t c) { ++counts[static_cast<std::size_t>(c)]; });
    return Status{};
  }));
  ChunkRuns runs;
  std::uint64_t inRun = 0;
  for (std::uint64_t c = 0; c < counts.size(); ++c) {
    const std::uint64_t n = counts[static_cast<std::size_t>(c)];
    if (n == 0) continue;
    if (runs.firstChunk.empty() || (inRun > 0 && inRun + n > runPoints)) {
      runs.firstChunk.push_back(runs.chunks.size());
      inRun = 0;
    }
    runs.chunks.push_back(c);
    runs.points.push_back(n);
    inRun += n;
  }
  runs.firstChunk.push_back(runs.chunks.size());
  return runs;
}

std::string runPath(const std::string& directory, std::size_t run) {
  return fmt::format("{}/run-{}.points", directory, run);
}

Status writeRuns(const std::string& cloudPath, const ChunkLayout& layout, double radius,
                 const ChunkRuns& runs, const std::string& directory) {
  assert(radius >= 0 && runs.points.size() == runs.chunks.size());
  std::vector<RecordWriter> writers;
  writers.reserve(runs.runCount());
  for (std::size_t r = 0; r < runs.runCount(); ++r) {
    Result<RecordWriter> writer = RecordWriter::create(runPath(directory, r), 256 << 10);
    if (!writer) return writer.status();
    writers.push_back(std::move(*writer));
  }
  std::vector<std::size_t> reached;
  LODFORGE_TRY(forEachRecordBlock(cloudPath, [&](std::span<const CloudRecord> block) {
    for (const CloudRecord& r : block) {
      reached.clear();
      forEachChunk(layout, layout.reach(r.position, radius),
                   [&](std::uint64_t c) { reached.push_back(runs.runOf(c)); });
      std::sort(reached.begin(), reached.end());
      reached.erase(std::unique(reached.begin(), reached.end()), reached.end());
      for (std::size_t run : reached) LODFORGE_TRY(writers[run].add(r));
    }
    return Status{};
  }));
  for (RecordWriter& writer : writers) LODFORGE_TRY(writer.finish());
  return {};
}

}  // namespace lodforge
