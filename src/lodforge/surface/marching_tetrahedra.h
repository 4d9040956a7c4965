// The zero set of corner values as triangles: each cubic cell split into the six tetrahedra of
// Freudenthal's (Kuhn's) subdivision, which meet face to face across cells, so the surface has
// no ambiguous case and no crack between cells or chunks. A vertex lies on a grid edge and is
// named by it (its lower corner and one of seven directions), so chunks that share a face share
// its vertices by name, and computes them from the same two values the same way (bit-identical).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/surface/grid.h"

namespace lodforge {

struct SurfacePiece {
  std::vector<Vec3d> positions;
  std::vector<Vec3f> normals;          // per vertex: the distance's gradient there, unit
  std::vector<Rgba8> colors;           // per vertex, when the points have colours
  std::vector<std::uint64_t> edges;    // per vertex: the grid edge it lies on (edgeKey)
  std::vector<std::uint32_t> indices;  // 3 per triangle, facing from negative to positive
};

// The name of the edge from global corner (i, j, k) in direction `d` (bit 0: +x, 1: +y, 2: +z;
// 1..7).
std::uint64_t edgeKey(const VoxelGrid& grid, std::uint64_t i, std::uint64_t j, std::uint64_t k,
                      int d);

// The triangles of the cells of `values` (every cell whose eight corners are known) within the
// corner box [first, first + size) (global corners; the whole of `values` when size is 0); a
// value of exactly zero counts as positive. A vertex's normal is the gradient of the values
// (central differences, one-sided where a neighbour is unknown or outside `values`) interpolated
// along its edge: with a corner of margin round the box it is the same in every box.
SurfacePiece polygonize(const VoxelGrid& grid, const CornerValues& values,
                        std::array<std::uint64_t, 3> first = {},
                        std::array<std::uint32_t, 3> size = {});

}  // namespace lodforge
