// `lodforge tiles` for meshes (large-meshes paper §3.2-3.4): the input streamed into chunks, the
// octree built over them, a GLB per tile (tile_content.h) and tileset.json (tileset_json.h),
// staged in the work directory and put in place when complete. glTF is y-up and 3D Tiles z-up,
// so contents are written rotated (x, z, -y) as the spec asks; bounding volumes stay in the
// tileset's z-up frame.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/io/image/image_codec.h"
#include "lodforge/surface/reconstruct.h"
#include "lodforge/tiles/georeference.h"
#include "lodforge/tiles/implicit_tiling.h"
#include "lodforge/tiles/memory_plan.h"
#include "lodforge/tiles/tile_atlas.h"
#include "lodforge/tiles/tile_content.h"
#include "lodforge/tiles/tileset_json.h"
#include "lodforge/tiling/chunk_input.h"
#include "lodforge/tiling/chunk_store.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

// tileset.json listing every tile, or an implicit one (implicit_tiling.h): its root and subtree
// files. Auto: implicit above kImplicitTilingAboveTiles tiles, where a listing grows to
// megabytes that a viewer reads whole before its first frame.
enum class ImplicitTiling : std::uint8_t { kAuto, kOn, kOff };
inline constexpr std::uint64_t kImplicitTilingAboveTiles = 10'000;

struct TilesOptions {
  ChunkInputOptions input;  // chunk size, buffers (its work directory is set by writeTiles)
  OctreeOptions octree;     // reduction, normal limit, levels, error samples
  TilesMemory memory = TilesMemory::kModerate;
  std::uint64_t memoryLimit = 0;  // bytes for the whole build, 0: none
  int threads = 0;                // moderate mode: 0 means every core
  // Continue an interrupted build from <out>.work: finished chunks and tiles are kept when the
  // input and the options are the same.
  bool resume = false;
  // Georeferencing: the model's (0, 0, 0) at this place, axes east, north, up (metres); or the
  // input in this CRS ("EPSG:32633"), placed through PROJ.
  std::optional<Geodetic> origin;
  std::string crs;
  std::string crsFrom = "--crs";    // where `crs` came from, for messages ("the CRS in x.laz")
  bool meshoptCompression = false;  // --compress meshopt: EXT_meshopt_compression contents
  bool quantize = true;             // KHR_mesh_quantization where it is invisible (tileQuantized)
  ImplicitTiling implicitTiling = ImplicitTiling::kAuto;
  int subtreeLevels = kSubtreeLevels;  // levels per subtree file of an implicit tileset
  // A point cloud: its surface reconstructed chunk by chunk into the leaves (surface_input.h).
  std::optional<ReconstructOptions> surface;
  // A textured input's: tile texture pages (size cap, gutters), their encoding, and the bytes
  // of source-image blocks held for baking them.
  AtlasOptions atlas;
  ImageEncodeOptions textureEncoding{.format = ImageFormat::kJpeg, .quality = 85};
  std::uint64_t textureCacheBytes = std::uint64_t{64} << 20;
};

struct TilesStats {
  std::optional<std::string> truncation;  // where a salvaged input was cut short
  std::vector<std::string> warnings;      // the reader's (a CAD part that did not mesh)
  std::uint64_t inputTriangles = 0;
  std::uint64_t leafTriangles = 0;  // after cutting at the chunk planes
  std::uint64_t tiles = 0, leaves = 0;
  int levels = 0;
  bool implicitTiling = false;  // written with implicit tiling (subtree files)
  double chunkSize = 0;
  std::uint64_t outputBytes = 0;
  double seconds = 0, chunkSeconds = 0;  // all, and reading + cutting into chunks
  bool streamed = false;                 // the input was never held in memory whole
  bool resumed = false;                  // chunks came from an interrupted run
  int threads = 0;
  std::uint64_t maxLockedVertices = 0, lockedVertices = 0, vertices = 0;  // over parents
  std::uint64_t droppedSegments = 0;        // small whole segments parents left out (over parents)
  std::optional<ReconstructStats> surface;  // --surface, when not resumed
  std::uint64_t parts = 0;                  // named parts (parts.json), 0: none
  std::uint64_t partsInRoot = 0;            // of them, those the coarsest tiles still hold
  // A job of several ranks (docs/distributed.md): how many, the level whose subtrees they
  // shared, each one's work (leaf triangles under its subtrees) and the octree's wall time.
  int ranks = 1;
  bool readInSlices = false;     // every rank read a slice of the input (chunk_ply.h)
  std::uint64_t builtNodes = 0;  // octree nodes this run built (all ranks)
  std::uint64_t takenNodes = 0;  // and those it took as an earlier, interrupted run left them
  int splitLevel = 0;
  std::vector<std::uint64_t> rankWork;
  double octreeSeconds = 0;
  std::vector<std::string> rankStages;  // per rank: bytes read and written by stage, peak memory
};

// Where `lodforge tiles -o OUT` works: OUT.work holds the work files and the tileset being
// staged, under a stable name so that --resume finds it.
std::string tilesWorkDirectory(const std::string& outputDirectory);
// Whether that work directory holds what --resume goes on from (finished chunks, or an
// interrupted surface reconstruction's runs).
bool tilesWorkKept(const std::string& workDirectory);

// `lodforge tiles`: the whole pipeline into `outputDirectory` (written under a temporary name
// and renamed when complete).
Result<TilesStats> writeTiles(const std::string& input, const std::string& outputDirectory,
                              const TilesOptions& options);

}  // namespace lodforge
