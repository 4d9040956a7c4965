// What chunking a PLY and chunking a model read whole share: the leaf size (how many
// triangles a leaf chunk holds, what --levels asks for, where the triangles crowd), normals
// carried through the input transform, and running on a limited number of threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include <tbb/task_arena.h>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_grid.h"
#include "lodforge/tiling/chunk_input.h"

namespace lodforge {

// Runs `work` on `threads` threads (0: as many as the process allows).
template <class Work>
void runOn(int threads, const Work& work) {
  if (threads <= 0) return work();
  tbb::task_arena arena(threads);
  arena.execute(work);
}

// A small model still gets a hierarchy to refine through: leaves of at most a sixteenth of it
// (not below 2 K triangles), so that a viewer shows a 30 K-triangle part from afar with a coarse
// tile instead of loading all of it.
std::uint64_t leafTriangles(const ChunkInputOptions& options, std::uint64_t triangles);

// The leaf chunks' edge: --chunk-size, or from the bounds and leafTriangles; with --levels N small
// enough for N levels above the leaves (the grid's longest side has 2^N cells), refused when that
// leaves fewer than 16 triangles per leaf of a surface.
Result<double> chunkSizeFor(const ChunkInputOptions& options, const Aabbd& bounds,
                            std::uint64_t triangles);

// The largest chunk edge, from the longest side down by steps of 2^(1/3), at which the chunks
// that hold triangles hold on average at most 1.5 x `perChunk` and none more than 1.5 x
// `mostPerChunk` (what memory allows a chunk). Parts clustered in a volume, as in a CAD
// assembly, crowd into far fewer chunks than a surface would; a few dense clusters do not drive
// the rest into slivers of leaves (halving while a triangle-weighted mean stayed high made
// leaves of a few hundred triangles, each cut triangle a fan of five). `visit(add)` calls
// add(point, triangles) for where the triangles are: each triangle's centroid, or each
// object's centre.
template <class Visit>
double fitChunkSize(const Aabbd& bounds, std::uint64_t perChunk, std::uint64_t mostPerChunk,
                    const Visit& visit) {
  const double longest = std::max(bounds.longestSide(), 1e-9), smallest = longest / 4096;
  const double step = std::cbrt(2.0);
  std::unordered_map<std::uint64_t, double> load;
  double size = longest;
  for (; size / step >= smallest; size /= step) {
    const ChunkGrid grid = ChunkGrid::over(bounds, size);
    load.clear();
    visit([&](Vec3d p, double triangles) { load[grid.cellIndex(grid.cellOf(p))] += triangles; });
    double triangles = 0, fullest = 0;
    for (const auto& [cell, count] : load) {
      triangles += count;
      fullest = std::max(fullest, count);
    }
    if (load.empty() ||
        (triangles / static_cast<double>(load.size()) <= 1.5 * static_cast<double>(perChunk) &&
         fullest <= 1.5 * static_cast<double>(mostPerChunk)))
      break;
  }
  return size;
}

// A normal carried through the input transform (a CRS to a local frame): the direction from the
// transformed point to the transformed point one unit along the normal. Without a transform, or
// where that fails, the normal as it was.
Vec3f transformNormal(const ChunkInputOptions& options, Vec3d in, Vec3d out, Vec3f normal);

}  // namespace lodforge
