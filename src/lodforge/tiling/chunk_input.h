// The input streamed into the chunk grid (large-meshes paper §3.3–3.4). A PLY is never held in
// memory: a first pass copies its vertices to a work file (exact doubles) and finds the bounds,
// a second pass reads the faces, fetches their corners through a fixed block cache over that
// file, cuts them and hands the pieces to the chunk files; an OBJ streams likewise (chunk_obj.h)
// unless its objects are to be parts. Other formats, and progressive packages (at full
// detail), are read whole first (their readers do not stream). Segments
// smaller than a chunk go in whole (ChunkWriter::addSegmentTriangle): connected components of
// each object for a model read whole, objects for a PLY with object ids.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "lodforge/core/image_source.h"
#include "lodforge/core/material.h"
#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/io/cad/cad_reader.h"
#include "lodforge/tiling/chunk_store.h"

namespace lodforge {

// Whether the objects of an input become parts (features, tile_features.h). Parts are never
// welded to one another, so a scan split into objects (an OBJ's groups) would keep open seams
// between them in coarse tiles: auto names parts for assemblies only.
enum class PartsMode : std::uint8_t {
  kAuto,  // CAD, glTF, assimp scenes and .lfp inputs of more than one object
  kOn,    // any input of more than one object
  kOff,
};

struct ChunkInputOptions {
  double chunkSize = 0;  // 0: from the bounds and trianglesPerChunk
  std::uint64_t trianglesPerChunk = 64 * 1024;
  std::uint64_t chunkBufferBytes = std::uint64_t{64} << 20;  // before chunk files are appended
  std::uint64_t vertexCacheBytes = std::uint64_t{64} << 20;  // PLY corner lookups
  std::string workDirectory;                                 // chunk files and the vertex file
  bool keepInMemory = false;  // chunks stay in memory (the unbounded mode), never written
  int threads = 0;            // reading, cutting and writing overlap on this many (0: all)
  // Applied to every input position before anything else (a CRS to a local frame); false:
  // the point cannot be transformed, which is bad input.
  std::function<bool(Vec3d, Vec3d&)> transform;
  // A PLY cut short: read up to its last whole element; a STEP or IFC: what it holds.
  bool salvageTruncated = false;
  CadReadOptions cad;  // tessellation of a CAD input
  PartsMode parts = PartsMode::kAuto;
  int levels = 0;  // levels the octree must be able to build above the leaves (0: any)
};

// The input's objects (CAD parts) by feature id (CutCorner::feature): what tiles name per vertex.
// Empty for an input of one object or none (a scan, a point cloud's surface).
struct PartTable {
  std::string source;              // the input file's name, without its folder
  std::vector<std::string> names;  // by feature id
  std::vector<std::string> paths;  // by feature id; empty strings where there is no assembly
  std::vector<Aabbd> bounds;       // by feature id, in the tileset's frame (empty: no triangles)
  std::vector<std::uint32_t> materials;  // by feature id: into `materialTable`, or kNoMaterial
  std::vector<Material> materialTable;
  std::vector<std::uint32_t> layers;    // by feature id: into `layerTable`, or kNoLayer
  std::vector<std::string> layerTable;  // CAD layer names (few)

  std::size_t size() const { return names.size(); }
  bool empty() const { return names.empty(); }
};

// A textured input's materials and images (the model's tables): what corners' materials
// (CutCorner::material) refer to. Empty for an input without textures.
struct TextureTable {
  std::vector<Material> materials;
  std::vector<ImageSource> images;

  bool empty() const { return images.empty(); }
};

struct ChunkInput {
  std::unique_ptr<ChunkWriter> chunks;
  std::uint64_t inputTriangles = 0;
  Aabbd bounds;
  bool colors = false;
  bool streamed = false;       // a PLY read in two passes, never whole
  std::optional<Mat4d> frame;  // the local frame's place on Earth (ECEF), when georeferenced
  std::optional<std::string> truncation;  // where a salvaged PLY was cut short
  std::vector<std::string> warnings;      // the reader's (a CAD part that did not mesh)
  PartTable parts;
  TextureTable textures;
  // Files beside the input that the chunks depend on (an OBJ's material libraries): a resumed
  // run checks them as it checks the input.
  std::vector<std::string> sideFiles;
};

Result<ChunkInput> chunkInput(const std::string& path, const ChunkInputOptions& options);

}  // namespace lodforge
