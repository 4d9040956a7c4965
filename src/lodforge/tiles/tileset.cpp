#include "lodforge/tiles/tileset.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/tiles/surface_input.h"
#include "lodforge/tiles/tile_texture.h"
#include "lodforge/tiles/tileset_output.h"
#include "lodforge/tiles/tileset_parts.h"
#include "lodforge/tiling/resume.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

// What identifies the input of a resumable run besides its path.
std::uint64_t fileBytes(const std::string& path) {
  Result<std::uint64_t> size = fileSize(path);
  return size ? *size : 0;
}

// The work directory (stable name, marked as ours) and the tileset staged inside it. On failure
// or Ctrl-C after the chunks are complete, it stays for --resume; otherwise (bad input, or
// success) it goes.
struct WorkPlace {
  ScopedDirectory work;
  ScopedDirectory staging;
  bool done = false;
  ~WorkPlace() {
    std::error_code ignored;
    if (!done && tilesWorkKept(work.path)) staging.path.clear(), work.path.clear();
  }
};

// Empties what a run makes again (all of it unless resuming) and creates the folders.
Status prepareWorkPlace(const WorkPlace& place, bool keepEarlierWork) {
  std::error_code error;
  if (!keepEarlierWork) {
    fs::remove_all(place.staging.path, error);
    fs::remove_all(place.work.path + "/nodes", error);
    fs::remove_all(place.work.path + "/chunks", error);  // chunk files are appended to
    // Texture pyramids and embedded images belong to the state they were made with: a
    // resumed run takes a pyramid by its size alone.
    fs::remove_all(place.work.path + "/textures", error);
    fs::remove_all(place.work.path + "/images", error);
    fs::remove(workStatePath(place.work.path), error);
  }
  fs::create_directories(fs::path(place.staging.path) / "tiles", error);
  if (!error) fs::create_directories(fs::path(place.work.path) / "nodes", error);
  if (error) return ioError(place.work.path, fmt::format("cannot create: {}", error.message()));
  return {};
}

// Georeferencing from a CRS: set up on the first input point (the local frame's origin).
struct LazyCrs {
  std::string crs;
  std::optional<CrsToLocal> transform;
  Status error;
};
std::shared_ptr<LazyCrs> attachCrs(const std::string& crs, const std::string& from,
                                   ChunkInputOptions& input) {
  auto lazy = std::make_shared<LazyCrs>(LazyCrs{crs, std::nullopt, {}});
  if (crs.empty()) return lazy;
  input.transform = [lazy, from](Vec3d in, Vec3d& out) {
    if (!lazy->transform) {
      Result<CrsToLocal> created = CrsToLocal::create(lazy->crs, in, from);
      if (!created) {
        lazy->error = created.status();
        return false;
      }
      lazy->transform = std::move(*created);
    }
    return lazy->transform->apply(in, out);
  };
  return lazy;
}

// What a reconstructed surface's chunks depend on (null: not a surface).
nlohmann::json surfaceIdentity(const std::optional<ReconstructOptions>& surface) {
  if (!surface) return nullptr;
  const Vec3d& view = surface->normals.viewpoint;
  return {{"voxel", surface->voxel},
          {"chunkVoxels", surface->chunkVoxels},
          {"chunkLength", surface->chunkLength},
          {"radius", surface->distance.radius},
          {"minPoints", surface->distance.minPoints},
          {"orientation", static_cast<int>(surface->normals.orientation)},
          {"viewpoint", {view.x, view.y, view.z}},
          {"minTriangles", surface->minTriangles},
          {"decimateVoxels", surface->decimateVoxels}};
}

// Everything the chunks depend on: a resumed run takes them only when this is unchanged.
nlohmann::json runIdentity(const std::string& path, const TilesOptions& options,
                           const ChunkInputOptions& input, const OctreeOptions& octree) {
  std::error_code error;
  // 3: textures in the state; work files of another format start over.
  return {{"workFormat", 3},
          {"input", fs::absolute(path, error).string()},
          {"bytes", fileBytes(path)},
          {"modified", modifiedTicks(path)},
          {"chunkSize", input.chunkSize},
          {"trianglesPerChunk", input.trianglesPerChunk},
          {"levels", input.levels},
          {"salvage", input.salvageTruncated},
          {"keep", octree.reduction},  // the key of earlier work directories
          {"maxNormalDeviation", octree.maxNormalDeviationDegrees},
          {"errorSamples", octree.errorSamples},
          {"crs", options.crs},
          {"meshopt", options.meshoptCompression},
          {"quantize", options.quantize},
          {"origin", options.origin ? fmt::format("{},{},{}", options.origin->longitude,
                                                  options.origin->latitude, options.origin->height)
                                    : ""},
          {"surface", surfaceIdentity(options.surface)},
          {"parts", static_cast<int>(input.parts)},
          {"cad",
           {input.cad.deflection, input.cad.absoluteDeflection, input.cad.angleDegrees,
            input.cad.codePage, input.cad.hidden}}};
}

// The reconstruction's options for --surface: it keeps its work for --resume too, unless a CRS
// places the points (its local frame is set up from the first point read, which a resumed
// reconstruction does not read again).
ReconstructOptions resumableSurface(const TilesOptions& options, const ChunkInputOptions& input) {
  ReconstructOptions surface = *options.surface;
  surface.resumable = !input.keepInMemory && options.crs.empty();
  surface.resume = options.resume;
  surface.placement = options.crs;
  return surface;
}

// Streams the input into the chunk grid, or takes the chunks of an interrupted run.
Result<ChunkInput> chunkOrResume(const std::string& path, const TilesOptions& options,
                                 const ChunkInputOptions& input, const OctreeOptions& octree,
                                 const WorkPlace& place, const LazyCrs& crs, bool& resumed,
                                 std::optional<ReconstructStats>& surface) {
  const std::string statePath = workStatePath(place.work.path);
  const nlohmann::json identity = runIdentity(path, options, input, octree);
  if (options.resume) {
    std::optional<ChunkInput> earlier =
        resumeChunks(statePath, identity, input.workDirectory + "/chunks");
    resumed = earlier.has_value();
    if (earlier) return std::move(*earlier);
  }
  LODFORGE_TRY(prepareWorkPlace(place, false));
  Result<ChunkInput> fresh =
      options.surface
          ? surfaceChunkInput(path, input, resumableSurface(options, input), surface.emplace())
          : chunkInput(path, input);
  if (!fresh) return crs.error.ok() ? fresh.status() : crs.error;
  if (options.origin) fresh->frame = eastNorthUpToEcef(*options.origin);
  if (crs.transform) fresh->frame = crs.transform->localToEcef();
  if (!input.keepInMemory) LODFORGE_TRY(saveChunkState(statePath, identity, *fresh));
  return fresh;
}

// Whether the tileset goes out with implicit tiling: asked for (refused where the octree is no
// single subdivision), or by its size.
Result<bool> implicitTilingWanted(ImplicitTiling wanted, const OctreeResult& tree) {
  const bool fits = implicitTilingFits(tree);
  if (wanted == ImplicitTiling::kOn && !fits)
    return Error{ErrorKind::kUsage,
                 "implicit tiling needs the octree up to a single root; --levels stopped it "
                 "below one"};
  if (wanted != ImplicitTiling::kAuto) return wanted == ImplicitTiling::kOn;
  const auto tiles = std::count_if(tree.nodes.begin(), tree.nodes.end(), hasTileContent);
  return fits && static_cast<std::uint64_t>(tiles) > kImplicitTilingAboveTiles;
}

// The octree over the chunks, each tile written into the staged tileset as soon as it is built.
Result<OctreeResult> buildTiles(const ChunkInput& chunked, const TilesOptions& options,
                                const OctreeOptions& octree, const std::string& tilesetDirectory,
                                const TileTexturing* texturing) {
  return buildOctree(
      *chunked.chunks, octree, [&](const OctreeNode& node, const MeshPart& mesh) -> Status {
        if (mesh.triangleCount() == 0) return {};
        return writeTileContent(mesh, node.bounds, tilesetDirectory + "/" + tileContentUri(node),
                                {.colors = chunked.colors,
                                 .meshoptCompression = options.meshoptCompression,
                                 .quantize = options.quantize && tileQuantized(node),
                                 .parts = &chunked.parts,
                                 .texturing = texturing,
                                 .level = static_cast<std::uint32_t>(node.level)});
      });
}

// A textured input's images as pyramids in the work directory, for every tile to bake from.
Result<std::optional<TexturePyramid>> buildPyramids(const ChunkInput& chunked,
                                                    const std::string& workDirectory,
                                                    const TexturePlan& plan, bool resumed) {
  if (chunked.textures.empty()) return std::optional<TexturePyramid>();
  for (const ImageSource& image : chunked.textures.images) {
    if (image.format == ImageFormat::kJpeg || plan.wholeImageBytes == 0 ||
        image.decodedBytes() <= plan.wholeImageBytes)
      continue;
    return Error{ErrorKind::kLimit,
                 fmt::format("{}: a {} image of {}x{} is decoded whole ({}), more than "
                             "--memory-limit leaves for it ({}); a JPEG is decoded row by row",
                             image.embedded() ? image.name : image.path,
                             imageFormatName(image.format), image.width, image.height,
                             formatBytes(image.decodedBytes()), formatBytes(plan.wholeImageBytes))};
  }
  const std::string directory = workDirectory + "/textures";
  std::error_code error;
  fs::create_directories(directory, error);
  if (error) return ioError(directory, fmt::format("cannot create: {}", error.message()));
  Result<TexturePyramid> pyramid =
      TexturePyramid::build(chunked.textures.images, directory, plan.cacheBytes, resumed);
  if (!pyramid) return pyramid.status();
  return std::optional(std::move(*pyramid));
}

void countChunks(const ChunkInput& chunked, TilesStats& stats) {
  stats.inputTriangles = chunked.inputTriangles;
  stats.truncation = chunked.truncation;
  stats.warnings = chunked.warnings;
  stats.streamed = chunked.streamed;
  stats.chunkSize = chunked.chunks->grid().size;
  stats.leafTriangles = chunked.chunks->triangleCount();
  stats.parts = chunked.parts.size();
}

void countTiles(const OctreeResult& tree, TilesStats& stats) {
  for (const OctreeNode& node : tree.nodes) {
    stats.tiles += node.triangles > 0 ? 1 : 0;
    stats.leaves += node.level == 0 ? 1 : 0;
    if (node.level > 0) {
      stats.lockedVertices += node.lockedVertices;
      stats.vertices += node.vertices;
      stats.droppedSegments += node.droppedSegments;
      stats.maxLockedVertices = std::max(stats.maxLockedVertices, node.lockedVertices);
    }
  }
  stats.levels = tree.levels;
  // The coarsest level with content (with --levels the root above it may have none).
  int top = 0;
  for (const OctreeNode& node : tree.nodes)
    if (node.triangles > 0) top = std::max(top, node.level);
  std::vector<std::uint32_t> coarsest;
  for (const OctreeNode& node : tree.nodes)
    if (node.level == top)
      coarsest.insert(coarsest.end(), node.features.begin(), node.features.end());
  std::sort(coarsest.begin(), coarsest.end());
  stats.partsInRoot =
      static_cast<std::uint64_t>(std::unique(coarsest.begin(), coarsest.end()) - coarsest.begin());
}

}  // namespace

bool tilesWorkKept(const std::string& workDirectory) {
  std::error_code ignored;
  return fs::exists(workStatePath(workDirectory), ignored) || surfaceWorkKept(workDirectory);
}

std::string tilesWorkDirectory(const std::string& outputDirectory) {
  return outputDirectory + ".work";
}

Result<TilesStats> writeTiles(const std::string& path, const std::string& outputDirectory,
                              const TilesOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  TilesStats stats;
  LODFORGE_TRY(claimTilesetOutput(path, outputDirectory));
  const std::string workDirectory = tilesWorkDirectory(outputDirectory);
  LODFORGE_TRY(claimWorkDirectory(workDirectory));  // before it is ours to remove
  WorkPlace place{ScopedDirectory(workDirectory), ScopedDirectory(workDirectory + "/tileset")};
  LODFORGE_TRY(prepareWorkPlace(place, options.resume));

  ChunkInputOptions input = options.input;
  OctreeOptions octree = options.octree;
  input.levels = octree.levels;
  input.workDirectory = workDirectory;
  octree.workDirectory = workDirectory + "/nodes";
  LODFORGE_TRY(
      planTilesMemory(options.memory, options.memoryLimit, options.threads, input, octree));
  stats.threads = octree.threads;
  const std::shared_ptr<const LazyCrs> crs = attachCrs(options.crs, options.crsFrom, input);

  Result<ChunkInput> chunked =
      chunkOrResume(path, options, input, octree, place, *crs, stats.resumed, stats.surface);
  if (!chunked) return chunked.status();
  countChunks(*chunked, stats);
  stats.chunkSeconds = secondsSince(start);

  octree.resume = stats.resumed;
  const TexturePlan plan = planTextureMemory(options.memoryLimit, octree.threads,
                                             options.atlas.maxSize, options.textureCacheBytes);
  Result<std::optional<TexturePyramid>> pyramid =
      buildPyramids(*chunked, workDirectory, plan, stats.resumed);
  if (!pyramid) return pyramid.status();
  AtlasOptions atlas = options.atlas;
  atlas.maxSize = plan.pageSide;
  TileTexturing texturing{&chunked->textures, *pyramid ? &**pyramid : nullptr, atlas,
                          options.textureEncoding};
  Result<OctreeResult> tree =
      buildTiles(*chunked, options, octree, place.staging.path, *pyramid ? &texturing : nullptr);
  if (!tree) return tree.status();
  const std::string partsUri = chunked->parts.empty() ? "" : kPartsFileName;
  Result<bool> implicit = implicitTilingWanted(options.implicitTiling, *tree);
  if (!implicit) return implicit.status();
  stats.implicitTiling = *implicit;
  // Contents are written under their explicit names: moved when implicit, or back where an
  // interrupted implicit attempt moved them.
  if (*implicit || stats.resumed) LODFORGE_TRY(placeContents(*tree, place.staging.path, *implicit));
  if (*implicit)
    LODFORGE_TRY(writeImplicitTileset(*tree, chunked->chunks->grid(), place.staging.path,
                                      chunked->frame, options.quantize, partsUri,
                                      options.subtreeLevels));
  else
    LODFORGE_TRY(writeTilesetJson(*tree, place.staging.path + "/tileset.json", chunked->frame,
                                  options.quantize, partsUri));
  if (!partsUri.empty())
    LODFORGE_TRY(writePartsJson(*tree, chunked->parts, place.staging.path + "/" + partsUri));
  countTiles(*tree, stats);
  stats.outputBytes = directoryBytes(place.staging.path);

  // Complete: replace the previous tileset, if any, by the new one.
  place.done = true;
  LODFORGE_TRY(replaceDirectory(place.staging, outputDirectory));
  stats.seconds = secondsSince(start);
  return stats;
}

}  // namespace lodforge
