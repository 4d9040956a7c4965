// The GLB content of a mesh tile (large-meshes paper §3.2): positions relative to the tile's
// centre, y-up as glTF wants, in vertex-cache order, optionally quantised or meshopt-compressed.
#pragma once

#include <string>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_input.h"
#include "lodforge/tiling/mesh_part.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

// The GLB of one tile: positions relative to the bounds' centre (float), that centre as the
// root translation, the mesh's normals (area-weighted over this mesh alone if it has none),
// colours when asked and the mesh has them, each vertex's part (tile_features.h) when the mesh
// has features and `parts` names them; triangles
// ordered for the vertex cache and vertices for fetch (meshoptimizer), optionally
// meshopt-compressed; textured triangles with the tile's own texture pages.
struct TileTexturing;
struct TileContentOptions {
  bool colors = true;
  bool meshoptCompression = false;
  bool quantize = false;  // KHR_mesh_quantization over the tile's box
  const PartTable* parts = nullptr;
  // A textured input's: the tile's texture is baked for its level (0: a leaf, the source's
  // resolution) into pages of its own (tile_texture.h).
  const TileTexturing* texturing = nullptr;
  std::uint32_t level = 0;
};
Status writeTileContent(const MeshPart& mesh, const Aabbd& bounds, const std::string& path,
                        const TileContentOptions& options = {});

// Whether a tile's content is quantised (KHR_mesh_quantization) when quantisation is on: always
// for leaves (16 bits over a box of ~64 K triangles put the grid a few hundred times finer than
// an edge), and for a parent when the grid's error stays under 1/32 of its geometric error,
// i.e. half a pixel wherever a viewer at 16 pixels of screen-space error shows it.
bool tileQuantized(const OctreeNode& node);
// The largest position error quantisation adds to a tile (half a grid step along each axis of
// its box), 0 when the tile is not quantised.
double tileQuantizationError(const OctreeNode& node, bool quantize);

// glTF is y-up, 3D Tiles z-up: a viewer turns content (x, y, z) into (x, -z, y), so contents
// are written as (x, z, -y).
inline Vec3f toYUp(Vec3f p) {
  return {p.x, p.z, -p.y};
}
inline Vec3d toYUp(Vec3d p) {
  return {p.x, p.z, -p.y};
}

}  // namespace lodforge
