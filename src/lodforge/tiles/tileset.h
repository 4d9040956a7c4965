// 3D Tiles 1.1 output (large-meshes paper §3.2): tileset.json over the octree and one GLB per
// tile. glTF is y-up and 3D Tiles z-up, so contents are written rotated (x, z, -y) as the spec
// asks; bounding volumes stay in the tileset's z-up frame.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/tiles/georeference.h"
#include "lodforge/tiling/chunk_input.h"
#include "lodforge/tiling/chunk_store.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

// The paper's memory modes (§3.4): one thread; a few threads (25 % of the cores unless
// --threads says otherwise); every core with chunks and node meshes kept in memory.
enum class TilesMemory : std::uint8_t { kMinimal, kModerate, kUnbounded };

struct TilesOptions {
  ChunkInputOptions input;  // chunk size, buffers (its work directory is set by writeTiles)
  OctreeOptions octree;     // reduction, normal limit, levels, error samples
  TilesMemory memory = TilesMemory::kModerate;
  std::uint64_t memoryLimit = 0;  // bytes for the whole build, 0: none
  int threads = 0;                // moderate mode: 0 means 25 % of the cores
  // Continue an interrupted build from <out>.work and <out>.partial: finished chunks and tiles
  // are kept when the input and the options are the same.
  bool resume = false;
  // Georeferencing: the model's (0, 0, 0) at this place, axes east, north, up (metres); or the
  // input in this CRS ("EPSG:32633"), placed through PROJ.
  std::optional<Geodetic> origin;
  std::string crs;
  bool meshoptCompression = false;  // --compress meshopt: EXT_meshopt_compression contents
  bool quantize = true;             // KHR_mesh_quantization where it is invisible (tileQuantized)
};

struct TilesStats {
  std::optional<std::string> truncation;  // where a salvaged input was cut short
  std::uint64_t inputTriangles = 0;
  std::uint64_t leafTriangles = 0;  // after cutting at the chunk planes
  std::uint64_t tiles = 0, leaves = 0;
  int levels = 0;
  double chunkSize = 0;
  std::uint64_t outputBytes = 0;
  double seconds = 0, chunkSeconds = 0;  // all, and reading + cutting into chunks
  bool streamed = false;                 // the input was never held in memory whole
  bool resumed = false;                  // chunks came from an interrupted run
  int threads = 0;
  std::uint64_t maxLockedVertices = 0, lockedVertices = 0, vertices = 0;  // over parents
  std::uint64_t droppedSegments = 0;  // small whole segments parents left out (over parents)
};

// The GLB of one tile: positions relative to the bounds' centre (float), that centre as the
// root translation, the mesh's normals (area-weighted over this mesh alone if it has none),
// colours when asked and the mesh has them; triangles
// ordered for the vertex cache and vertices for fetch (meshoptimizer), optionally
// meshopt-compressed.
struct TileContentOptions {
  bool colors = true;
  bool meshoptCompression = false;
  bool quantize = false;  // KHR_mesh_quantization over the tile's box
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

// tileset.json for a built octree: asset 1.1, REPLACE refinement, box volumes, geometric errors,
// contents at tiles/<name>.glb for the nodes with triangles, and the root's transform (local
// frame to ECEF) when georeferenced. With `quantized` contents, each geometric error also holds
// the largest quantisation error in the tile's subtree (still non-increasing parent to child).
Status writeTilesetJson(const OctreeResult& octree, const std::string& path,
                        const std::optional<Mat4d>& rootTransform = std::nullopt,
                        bool quantized = false);

// glTF is y-up, 3D Tiles z-up: a viewer turns content (x, y, z) into (x, -z, y), so contents
// are written as (x, z, -y).
inline Vec3f toYUp(Vec3f p) {
  return {p.x, p.z, -p.y};
}
inline Vec3d toYUp(Vec3d p) {
  return {p.x, p.z, -p.y};
}

// A tile's "box" bounding volume for axis-aligned bounds: centre, then three half-axes.
std::array<double, 12> tileBox(const Aabbd& bounds);

// The relative URI of a node's content.
std::string tileContentUri(const OctreeNode& node);

// `lodforge tiles`: the whole pipeline into `outputDirectory` (written under a temporary name
// and renamed when complete).
Result<TilesStats> writeTiles(const std::string& input, const std::string& outputDirectory,
                              const TilesOptions& options);

}  // namespace lodforge
