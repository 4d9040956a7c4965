// 3D Tiles 1.1 output (large-meshes paper §3.2): tileset.json over the octree and one GLB per
// tile. glTF is y-up and 3D Tiles z-up, so contents are written rotated (x, z, -y) as the spec
// asks; bounding volumes stay in the tileset's z-up frame.
#pragma once

#include <cstdint>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_store.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

struct TilesOptions {
  double chunkSize = 0;                        // 0: from the bounds and trianglesPerLeaf
  std::uint64_t trianglesPerLeaf = 64 * 1024;  // target for the derived chunk size
  OctreeOptions octree;
  std::uint64_t chunkBufferBytes = std::uint64_t{256} << 20;
};

struct TilesStats {
  std::uint64_t inputTriangles = 0;
  std::uint64_t leafTriangles = 0;  // after cutting at the chunk planes
  std::uint64_t tiles = 0, leaves = 0;
  int levels = 0;
  double chunkSize = 0;
  std::uint64_t outputBytes = 0;
  double seconds = 0;
};

// The GLB of one tile: positions relative to the bounds' centre (float), that centre as the
// root translation, area-weighted normals, colours when the mesh has them.
Status writeTileContent(const MeshPart& mesh, const Aabbd& bounds, const std::string& path);

// tileset.json for a built octree: asset 1.1, REPLACE refinement, box volumes, geometric errors,
// contents at tiles/<name>.glb for the nodes with triangles.
Status writeTilesetJson(const OctreeResult& octree, const std::string& path);

// The relative URI of a node's content.
std::string tileContentUri(const OctreeNode& node);

// `lodforge tiles`: the whole pipeline into `outputDirectory` (written under a temporary name
// and renamed when complete).
Result<TilesStats> writeTiles(const std::string& input, const std::string& outputDirectory,
                              const TilesOptions& options);

}  // namespace lodforge
