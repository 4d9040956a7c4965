#include "lodforge/surface/piece_decimation.h"

#include <cstdint>
#include <vector>

#include "lodforge/simplify/progressive.h"

namespace lodforge {

SurfacePiece decimatePiece(const ChunkLayout& layout, SurfacePiece piece, double maxError) {
  if (!(maxError > 0) || piece.indices.empty()) return piece;
  // Floats relative to the piece's first vertex: even a 4096-voxel chunk keeps them to about
  // 1e-4 voxels, far inside any bound worth asking.
  const Vec3d origin = piece.positions.front();
  std::vector<Vec3f> positions(piece.positions.size());
  std::vector<std::uint8_t> locked(piece.positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    positions[v] = toFloat(piece.positions[v] - origin);
    locked[v] = layout.onChunkFace(piece.edges[v]) ? 1 : 0;
  }
  ProgressiveOptions options;
  options.locked = locked;
  options.maxError = maxError;
  const SimplifiedMesh simplified = simplifyMesh(positions, piece.indices, options);
  SurfacePiece out;
  out.positions.reserve(simplified.vertices.size());
  out.normals.reserve(simplified.vertices.size());
  out.edges.reserve(simplified.vertices.size());
  for (const std::uint32_t v : simplified.vertices) {
    out.positions.push_back(piece.positions[v]);
    out.normals.push_back(piece.normals[v]);
    out.edges.push_back(piece.edges[v]);
    if (!piece.colors.empty()) out.colors.push_back(piece.colors[v]);
  }
  out.indices = simplified.indices;
  return out;
}

}  // namespace lodforge
