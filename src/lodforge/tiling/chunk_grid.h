// The chunk grid of the large-meshes paper (§3.3): cubes of one edge length from a corner.
// Triangles that cross a chunk plane are cut exactly on it. Where an edge meets a plane is
// computed from the edge's two ends taken in a fixed order, with the plane coordinate set
// exactly, so both pieces of a cut, and both triangles on a shared edge, get bit-identical new
// vertices — the border vertices that the octree later welds and keeps locked.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/math.h"

namespace lodforge {

// A chunk's integer coordinates on the grid.
using ChunkCell = std::array<std::int32_t, 3>;

struct ChunkGrid {
  Vec3d origin;      // the corner of cell (0, 0, 0)
  double size = 1;   // edge length of a chunk
  ChunkCell dims{};  // cells per axis; every point of the input lies in [0, dims)

  // The grid over `bounds` with cubes of edge `size` (the bounds' corner is the origin).
  static ChunkGrid over(const Aabbd& bounds, double size);
  // A chunk edge for about `trianglesPerChunk` of `triangles` spread over a surface in `bounds`:
  // surfaces (scans, terrain) fill a chunk's cross-section, not its volume.
  static double sizeFor(const Aabbd& bounds, std::uint64_t triangles,
                        std::uint64_t trianglesPerChunk);

  double plane(int axis, std::int32_t k) const { return origin[axis] + size * k; }
  // The cell holding p (clamped into the grid: points on the far faces belong to the last cell).
  ChunkCell cellOf(Vec3d p) const;
  Aabbd cellBounds(const ChunkCell& cell) const;
  std::uint64_t cellIndex(const ChunkCell& cell) const {
    return (static_cast<std::uint64_t>(cell[2]) * static_cast<std::uint64_t>(dims[1]) +
            static_cast<std::uint64_t>(cell[1])) *
               static_cast<std::uint64_t>(dims[0]) +
           static_cast<std::uint64_t>(cell[0]);
  }
};

// The input object (a CAD part) a vertex belongs to, or none (a scan, a reconstructed surface).
inline constexpr std::uint32_t kNoFeature = ~0u;

// A corner of a triangle being cut: exact position, colour and unit normal (the input's, or
// area-weighted over the whole input, so tiles agree on the normals of the vertices they share),
// the input vertex it is (kNoSource for a vertex made by cutting): a chunk stores an input
// vertex once however many of its triangles use it; and its object (all three corners of a
// triangle have the same, and so do the pieces cut from it).
struct CutCorner {
  static constexpr std::uint64_t kNoSource = ~std::uint64_t{0};
  Vec3d position;
  Rgba8 color;
  Vec3f normal;
  std::uint64_t source = kNoSource;
  std::uint32_t feature = kNoFeature;
  // A textured input's texture coordinate and material (into ChunkInput::textures; kNoMaterial
  // for a corner of no texture): a vertex of each side of a UV seam.
  Vec2f uv{};
  std::uint32_t material = ~0u;
};

// Cuts one triangle at every grid plane it crosses and returns the pieces, each inside one cell:
// `cells` gets a cell per piece, `corners` 3 corners per piece. A piece that came out as a
// polygon is fanned around its centroid (an interior point, so no piece edge is lost and no
// T-junction appears on a border). Pieces without area (a corner touching a plane) are dropped.
void cutTriangle(const ChunkGrid& grid, const std::array<CutCorner, 3>& triangle,
                 std::vector<ChunkCell>& cells, std::vector<CutCorner>& corners);

}  // namespace lodforge
