// The mesh the octree passes between levels (large-meshes paper §3.3): indexed, with exact
// (double) positions and each vertex's part; a chunk once welded, a node once simplified. Its
// features, and the parts joined into one mesh.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/tiling/chunk_grid.h"

namespace lodforge {

// An indexed mesh with exact (double) positions: what the octree passes between levels.
struct MeshPart {
  std::vector<Vec3d> positions;
  std::vector<Rgba8> colors;   // empty or one per vertex
  std::vector<Vec3f> normals;  // empty or one unit normal per vertex
  // Empty or one per vertex: the input object (part) it belongs to, or kNoFeature. Vertices of
  // different objects are never welded, so no triangle spans two objects.
  std::vector<std::uint32_t> features;
  // A textured input's: empty or one per vertex, the texture coordinate and the material (into
  // the input's texture table, kNoMaterial for none). Vertices of different UVs or materials are
  // never welded: a UV seam is a pair of vertices at one position.
  std::vector<Vec2f> uvs;
  std::vector<std::uint32_t> materials;
  std::vector<std::uint32_t> indices;

  std::uint32_t vertexCount() const { return static_cast<std::uint32_t>(positions.size()); }
  std::uint64_t triangleCount() const { return indices.size() / 3; }
  std::uint64_t memoryBytes() const {
    return positions.size() * sizeof(Vec3d) + colors.size() * sizeof(Rgba8) +
           normals.size() * sizeof(Vec3f) + uvs.size() * sizeof(Vec2f) +
           (features.size() + materials.size() + indices.size()) * sizeof(std::uint32_t);
  }
};

// The mesh's features (kNoFeature left out), ascending, each once.
std::vector<std::uint32_t> distinctFeatures(const MeshPart& mesh);

// Appends `parts`, renumbering their indices.
MeshPart concatenate(std::span<const MeshPart> parts);

}  // namespace lodforge
