// What chunking a PLY and chunking a model read whole share: the leaf size (how many
// triangles a leaf chunk holds, what --levels asks for, where the triangles crowd), normals
// carried through the input transform, and running on a limited number of threads.
#pragma once

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

// The surface estimate of ChunkGrid::sizeFor, halved while the chunk a triangle lands in holds
// on average more than 1.5 x the target (parts clustered in a volume, as in a CAD assembly,
// crowd into far fewer chunks than a surface would). `visit(add)` calls add(point, triangles)
// for where the triangles are: each triangle's centroid, or each object's centre.
template <class Visit>
double fitChunkSize(const Aabbd& bounds, double size, std::uint64_t perChunk, const Visit& visit) {
  const double smallest = bounds.longestSide() / 4096;
  std::unordered_map<std::uint64_t, double> load;
  while (size / 2 >= smallest) {
    const ChunkGrid grid = ChunkGrid::over(bounds, size);
    load.clear();
    visit([&](Vec3d p, double triangles) { load[grid.cellIndex(grid.cellOf(p))] += triangles; });
    double squares = 0, triangles = 0;
    for (const auto& [cell, count] : load) {
      squares += count * count;
      triangles += count;
    }
    if (squares / triangles <= 1.5 * static_cast<double>(perChunk)) break;
    size /= 2;
  }
  return size;
}

// A normal carried through the input transform (a CRS to a local frame): the direction from the
// transformed point to the transformed point one unit along the normal. Without a transform, or
// where that fails, the normal as it was.
Vec3f transformNormal(const ChunkInputOptions& options, Vec3d in, Vec3d out, Vec3f normal);

}  // namespace lodforge
