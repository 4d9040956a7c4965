// A parent tile's mesh from its children's (large-meshes paper §3.3): welded along their shared
// borders, simplified to the reduction with its outer faces locked (the input's own rims and the
// seams inside it may move), small whole segments left out while it is over its target, and its
// geometric error measured (sampled Hausdorff both ways, the removed vertices' bound).
#pragma once

#include <cstdint>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/tiling/chunk_grid.h"
#include "lodforge/tiling/mesh_part.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

struct SimplifiedNode {
  MeshPart mesh;
  // The error against the children's geometry, and the bound on what leaving small segments out
  // costs; the node's geometric error adds both to its children's largest.
  double simplificationError = 0, droppedError = 0;
  std::uint64_t lockedVertices = 0;   // border vertices the simplification had to keep
  std::uint64_t droppedSegments = 0;  // small whole segments left out
};

// `node` gives the cell, level and bounds (the union of its children's); `children` are taken.
SimplifiedNode simplifyNode(std::vector<MeshPart> children, const ChunkGrid& grid,
                            const OctreeNode& node, const OctreeOptions& options);

// Tight bounds of a mesh's positions.
Aabbd boundsOf(const MeshPart& mesh);

}  // namespace lodforge
