#include "lodforge/surface/marching_tetrahedra.h"

#include <cmath>
#include <cstring>
#include <map>
#include <utility>

#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"

namespace lodforge {
namespace {

// Corner values of a sphere's signed distance over a box of the grid.
CornerValues sphereValues(const VoxelGrid& grid, std::array<std::uint64_t, 3> first,
                          std::array<std::uint32_t, 3> size, Vec3d centre, double radius) {
  CornerValues v{first, size, {}};
  v.values.resize(static_cast<std::size_t>(size[0]) * size[1] * size[2]);
  for (std::uint32_t k = 0; k < size[2]; ++k)
    for (std::uint32_t j = 0; j < size[1]; ++j)
      for (std::uint32_t i = 0; i < size[0]; ++i)
        v.values[v.index(i, j, k)] = static_cast<float>(
            length(grid.position(first[0] + i, first[1] + j, first[2] + k) - centre) - radius);
  return v;
}

// A sphere comes out closed, on the sphere to within the interpolation's error, every
// triangle facing out.
TEST(MarchingTetrahedra, ASphereIsClosedAndFacesOut) {
  VoxelGrid grid{{-1, -1, -1}, 0.1, {21, 21, 21}};
  const Vec3d centre{0.03, -0.02, 0.01};
  const SurfacePiece piece =
      polygonize(grid, sphereValues(grid, {0, 0, 0}, {21, 21, 21}, centre, 0.7));
  ASSERT_GT(piece.indices.size(), 300u);
  EXPECT_EQ(countBoundaryEdges(piece.indices), 0u);
  for (const Vec3d& p : piece.positions) EXPECT_NEAR(length(p - centre), 0.7, 0.01);
  for (std::size_t t = 0; t < piece.indices.size(); t += 3) {
    const Vec3d a = piece.positions[piece.indices[t]], b = piece.positions[piece.indices[t + 1]],
                c = piece.positions[piece.indices[t + 2]];
    EXPECT_GT(dot(cross(b - a, c - a), (a + b + c) * (1.0 / 3) - centre), 0) << t / 3;
  }
}

// Two boxes sharing a face of corners give the vertices of that face under the same names with
// the same bits, and joined by name they make the same closed surface as one box.
TEST(MarchingTetrahedra, BoxesSharingAFaceShareItsVerticesBitForBit) {
  VoxelGrid grid{{-1, -1, -1}, 0.1, {21, 21, 21}};
  const Vec3d centre{0.01, 0.02, -0.03};
  const SurfacePiece low =
      polygonize(grid, sphereValues(grid, {0, 0, 0}, {11, 21, 21}, centre, 0.66));
  const SurfacePiece high =
      polygonize(grid, sphereValues(grid, {10, 0, 0}, {11, 21, 21}, centre, 0.66));
  std::map<std::uint64_t, Vec3d> lowByEdge;
  for (std::size_t v = 0; v < low.positions.size(); ++v) lowByEdge[low.edges[v]] = low.positions[v];
  std::size_t shared = 0;
  for (std::size_t v = 0; v < high.positions.size(); ++v) {
    const auto found = lowByEdge.find(high.edges[v]);
    if (found == lowByEdge.end()) continue;
    ++shared;
    EXPECT_EQ(std::memcmp(&found->second, &high.positions[v], sizeof(Vec3d)), 0);
  }
  EXPECT_GT(shared, 20u);
  // Joined by edge name: closed.
  std::map<std::uint64_t, std::uint32_t> index;
  std::vector<std::uint32_t> joined;
  for (const SurfacePiece* piece : {&low, &high})
    for (std::uint32_t i : piece->indices)
      joined.push_back(index.try_emplace(piece->edges[i], static_cast<std::uint32_t>(index.size()))
                           .first->second);
  EXPECT_EQ(countBoundaryEdges(joined), 0u);
  const SurfacePiece whole =
      polygonize(grid, sphereValues(grid, {0, 0, 0}, {21, 21, 21}, centre, 0.66));
  EXPECT_EQ(joined.size(), whole.indices.size());
  EXPECT_EQ(index.size(), whole.positions.size());
}

// Unknown corners (NaN) make no surface in their cells: an open edge there, nothing bridged.
TEST(MarchingTetrahedra, UnknownCornersLeaveTheirCellsEmpty) {
  VoxelGrid grid{{0, 0, 0}, 1, {6, 6, 6}};
  CornerValues v{{0, 0, 0}, {6, 6, 6}, std::vector<float>(216)};
  for (std::uint32_t k = 0; k < 6; ++k)
    for (std::uint32_t j = 0; j < 6; ++j)
      for (std::uint32_t i = 0; i < 6; ++i)
        v.values[v.index(i, j, k)] = i >= 4 ? NAN : static_cast<float>(k) - 2.5f;
  const SurfacePiece piece = polygonize(grid, v);
  ASSERT_FALSE(piece.indices.empty());
  for (const Vec3d& p : piece.positions) {
    EXPECT_LE(p.x, 3.0);
    EXPECT_DOUBLE_EQ(p.z, 2.5);
  }
  EXPECT_GT(countBoundaryEdges(piece.indices), 0u);
}

}  // namespace
}  // namespace lodforge
