// `lodforge tiles INPUT -o DIR`: a mesh of any size as a 3D Tiles 1.1 tileset (large-meshes
// paper §3.2–3.4): chunk grid, octree of simplified super-chunks, one GLB per tile.
#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

#include "cad_options.h"
#include "cli.h"
#include "lodforge/core/cluster.h"
#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/output_claim.h"
#include "lodforge/core/units.h"
#include "lodforge/io/format_advice.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/model_io.h"
#include "lodforge/io/points/point_reader.h"
#include "lodforge/surface/reconstruct.h"
#include "lodforge/tiles/point_attributes.h"
#include "lodforge/tiles/point_tiles.h"
#include "lodforge/tiles/tileset.h"
#include "lodforge/tiles/tileset_output.h"
#include "lodforge/tiles/tileset_parts.h"
#include "lodforge/tiling/resume.h"
#include "surface_options.h"

namespace lodforge::cli {

namespace {

// A point cloud: a point file by its extension, or a PLY without faces.
bool isPointInput(const std::string& path) {
  if (isPointCloudPath(path)) return true;
  if (fileExtension(path) != "ply") return false;
  Result<PlyReader> ply = PlyReader::open(path, {.salvageTruncated = true});
  return ply.ok() && ply->header().faceCount == 0 && ply->header().vertexCount > 0;
}

Status checkTilesInput(const std::string& path) {
  LODFORGE_TRY(refuseDirectoryInput(path));
  if (!isPointCloudPath(path) && fileExtension(path) != "lfp" &&
      formatFromPath(path) == FileFormat::kUnknown)
    return unknownFormatError(
        path, fmt::format("{}, {}, and .lfp packages", kMeshFormats, kPointFormats));
  return checkInputPath(path);
}

// A tileset without a place on Earth sits at the Earth's centre in CesiumJS: say so.
void warnIfNotPlaced(const Global& global, bool placed) {
  if (placed || global.verbosity < 0) return;
  fmt::print(stderr,
             "lodforge: note: the tileset has no place on Earth (CesiumJS shows it at the "
             "Earth's centre); place it with --origin LON,LAT,HEIGHT or --crs EPSG:N\n");
}

// What `lodforge tiles` takes on the command line.
struct TilesCommand {
  std::string input, output;
  double chunkSize = 0;
  int levels = 0;
  double reduction = 0.2;
  double maxNormalDeviation = 30;
  std::string memory = "moderate";
  bool resume = false;
  std::string origin, crs;
  std::string compress = "auto";
  std::string implicitTiling = "auto";
  bool noQuantization = false;
  std::string parts = "auto";
  std::uint64_t blockSize = 50'000;
  std::uint64_t tilePoints = 50'000;
  std::string attributes = "all";
  bool salvage = false;
  std::uint32_t textureSize = 4096;
  std::string textureFormat = "jpeg";
  int textureQuality = 85;
  bool surface = false;  // point clouds: reconstruct a surface and tile it as a mesh
  SurfaceCommand surfaceOptions;
  CadCommand cad;
};

// Textured meshes: the tile texture pages and their encoding.
void addTextureOptions(CLI::App& sub, TilesCommand& options) {
  sub.add_option("--texture-size", options.textureSize,
                 "Textured meshes: a tile texture page's side at most, in texels (a tile whose "
                 "texels need more gets several pages; default 4096)")
      ->check(CLI::Range(64u, 16384u));
  sub.add_option("--texture-format", options.textureFormat,
                 "Textured meshes: jpeg (default; PNG where the source has alpha), png, or webp "
                 "(EXT_texture_webp: viewers without it draw no texture)")
      ->check(CLI::IsMember({"jpeg", "png", "webp"}));
  sub.add_option("--texture-quality", options.textureQuality,
                 "Textured meshes: JPEG or WebP quality, 1 to 100 (default 85)")
      ->check(CLI::Range(1, 100));
}

// Point clouds: the block partition and the fields carried.
void addPointCloudOptions(CLI::App& sub, TilesCommand& options) {
  addCountOption(sub, "--block-size", options.blockSize,
                 "Point clouds: most points per leaf tile (a block of the partition; default 50K)");
  addCountOption(sub, "--tile-points", options.tilePoints,
                 "Point clouds: about this many points in a tile above the blocks (default 50K)");
  sub.add_option("--attributes", options.attributes,
                 "Point clouds: the fields the tiles carry, comma-separated: classification, "
                 "intensity, returns, flags, scan-angle, user-data, point-source, gps-time, nir, "
                 "extras (LAS extra bytes, other PLY properties); or all (default: all the input "
                 "has) or none");
}

void addTilesOptions(CLI::App& sub, TilesCommand& options) {
  sub.add_option("INPUT", options.input,
                 "A .ply .obj .stl .gltf or .glb mesh or assembly, a .step .iges .brep CAD file, "
                 "an .lfp package, or a point cloud (.las .laz .xyz .txt .csv .pts, or a PLY "
                 "without faces)")
      ->required();
  sub.add_option("-o,--output", options.output, "The tileset directory to write")->required();
  sub.add_option("--chunk-size", options.chunkSize,
                 "Meshes: edge of a leaf chunk in model units (default: about 64K triangles per "
                 "leaf); with --surface, in the cloud's units (default 64 voxels)")
      ->check(CLI::NonNegativeNumber);
  sub.add_option("--levels", options.levels,
                 "Meshes: levels above the leaves; leaves are made small enough for them "
                 "(default: up to one root)")
      ->check(CLI::NonNegativeNumber);
  sub.add_option("--reduction", options.reduction,
                 "Share of its children's triangles a parent tile keeps (default 0.2)")
      ->check(CLI::Range(0.0, 1.0));
  sub.add_option("--max-normal-deviation", options.maxNormalDeviation,
                 "Largest angle in degrees a simplification step may turn a face (default 30)")
      ->check(CLI::Range(0.0, 90.0));
  sub.add_option("--memory", options.memory,
                 "minimal (one thread), moderate (--threads, default every core, the nodes being "
                 "built at once held to 512 MiB) or unbounded (every core, chunks kept in memory); "
                 "--memory-limit caps the whole build")
      ->check(CLI::IsMember({"minimal", "moderate", "unbounded"}));
  sub.add_option("--origin", options.origin,
                 "Place the model's (0,0,0) at LON,LAT,HEIGHT (degrees, metres) with x east, y "
                 "north, z up");
  sub.add_option("--crs", options.crs,
                 "The input's coordinate system (e.g. EPSG:32633), placed on Earth through PROJ");
  sub.add_option("--compress", options.compress,
                 "meshopt: EXT_meshopt_compression (smaller tiles; CesiumJS and three.js decode "
                 "it), none, or auto (meshopt for point clouds, none for meshes)")
      ->check(CLI::IsMember({"auto", "none", "meshopt"}));
  sub.add_option("--implicit-tiling", options.implicitTiling,
                 "Meshes: on (tileset.json holds the root; subtree files say which tiles exist, "
                 "each tile's error and box in their metadata), off (every tile listed), or auto "
                 "(on above 10,000 tiles)")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  sub.add_flag("--no-quantization", options.noQuantization,
               "Float positions and normals everywhere instead of KHR_mesh_quantization (16-bit "
               "positions, 8-bit normals) in the tiles where it is invisible");
  sub.add_option("--parts", options.parts,
                 "Meshes: name each object (part) in the tiles, pickable in viewers: auto (CAD, "
                 "glTF, FBX/DAE/IFC and .lfp inputs of several objects), on (any input of "
                 "several objects, which keeps objects from welding together), or off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  addTextureOptions(sub, options);
  addPointCloudOptions(sub, options);
  sub.add_flag("--surface", options.surface,
               "Point clouds: reconstruct a surface (as `lodforge reconstruct`), its chunks the "
               "leaves (--chunk-size: their edge, default 64 voxels); the options marked "
               "Surface go with it");
  addSurfaceOptions(sub, options.surfaceOptions);
  addCadOptions(sub, options.cad);
  sub.add_flag("--salvage", options.salvage,
               "Read a PLY, STEP or IFC cut short up to the cut (with a warning)");
  sub.add_flag("--resume", options.resume,
               "Continue an interrupted run from OUTPUT.work (same input and options)");
}

// The command line as the mesh pipeline's options.
Result<TilesOptions> meshTilesOptions(const Global& global, const TilesCommand& options) {
  TilesOptions tiles;
  tiles.input.chunkSize = options.chunkSize;
  tiles.input.salvageTruncated = options.salvage;
  Result<CadReadOptions> cad = cadOptions(options.cad, global);
  if (!cad) return cad.status();
  tiles.input.cad = *cad;
  tiles.octree.levels = options.levels;
  tiles.octree.reduction = options.reduction;
  tiles.octree.maxNormalDeviationDegrees = options.maxNormalDeviation;
  tiles.memory = options.memory == "minimal"     ? TilesMemory::kMinimal
                 : options.memory == "unbounded" ? TilesMemory::kUnbounded
                                                 : TilesMemory::kModerate;
  tiles.threads = static_cast<int>(global.threads);
  tiles.memoryLimit = global.memoryLimit;
  tiles.resume = options.resume;
  tiles.crs = options.crs;
  tiles.meshoptCompression = options.compress == "meshopt";
  tiles.quantize = !options.noQuantization;
  tiles.implicitTiling = options.implicitTiling == "on"    ? ImplicitTiling::kOn
                         : options.implicitTiling == "off" ? ImplicitTiling::kOff
                                                           : ImplicitTiling::kAuto;
  if (tiles.implicitTiling == ImplicitTiling::kOn && options.levels > 0)
    return Error{ErrorKind::kUsage,
                 "--implicit-tiling on and --levels: implicit tiling needs the octree up to a "
                 "single root"};
  tiles.atlas.maxSize = options.textureSize;
  tiles.textureEncoding = {.format = options.textureFormat == "png"    ? ImageFormat::kPng
                                     : options.textureFormat == "webp" ? ImageFormat::kWebp
                                                                       : ImageFormat::kJpeg,
                           .quality = options.textureQuality};
  tiles.input.parts = options.parts == "on"    ? PartsMode::kOn
                      : options.parts == "off" ? PartsMode::kOff
                                               : PartsMode::kAuto;
  if (!options.origin.empty()) {
    if (!options.crs.empty())
      return Error{ErrorKind::kUsage,
                   "--origin and --crs: give one (a CRS already places the model)"};
    Result<Geodetic> origin = parseOrigin(options.origin);
    if (!origin) return origin.status();
    tiles.origin = *origin;
  }
  return tiles;
}

// -v for a job of several ranks: each rank's share of the ranking and of the tiles, its stages.
void reportPointRanks(const Global& global, const PointTilesStats& stats) {
  std::string shares;
  for (std::size_t r = 0; r < stats.rankPoints.size(); ++r) {
    const std::uint64_t tiles = r < stats.rankTiles.size() ? stats.rankTiles[r] : 0;
    shares +=
        fmt::format("{}rank {} split and ranked {} points, wrote {} tile{}", r == 0 ? "" : "; ", r,
                    formatCount(stats.rankPoints[r]), formatCount(tiles), tiles == 1 ? "" : "s");
  }
  const std::string split =
      stats.resumed ? "the input as the interrupted job split it"
                    : fmt::format(
                          "the input read {} (done at {:.1f} s); the partition's large nodes split "
                          "level by level by the ranks ({:.1f} s)",
                          stats.readInSlices ? "in slices by every rank" : "by rank 0",
                          stats.readSeconds, stats.partitionSeconds);
  detail(global, fmt::format("{} ranks: {}, the rest split and ranked by each rank ({:.1f} s); {}",
                             stats.ranks, split, stats.rankingSeconds, shares));
  for (const std::string& line : stats.rankStages) detail(global, line);
}

// After a failed run: where its finished work stays for --resume, if it does.
void sayWorkKept(const std::string& output) {
  const std::string work = tilesWorkDirectory(output);
  // Not where another run holds the work (this one was refused), and once for a job.
  if (clusterRank() == 0 && isWorkDirectory(work) && tilesWorkKept(work) &&
      !workDirectoryLocked(work))
    fmt::print(stderr,
               "lodforge: the finished work is kept in {}: run again with --resume to continue, "
               "or delete it\n",
               work);
}

Status runPointTiles(const Global& global, const TilesCommand& options, const TilesOptions& tiles) {
  if (options.levels > 0 || options.chunkSize > 0)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: a point cloud; --levels and --chunk-size are for meshes (a "
                             "point tileset's depth follows --block-size)",
                             options.input)};
  if (options.implicitTiling == "on")
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: a point cloud; --implicit-tiling is for meshes (point tiles "
                             "split at centroids, not into the equal octants implicit tiling "
                             "describes)",
                             options.input)};
  PointTilesOptions points;
  points.blockSize = std::max<std::uint64_t>(1, options.blockSize);
  points.tilePoints = std::max<std::uint64_t>(1, options.tilePoints);
  points.memoryLimit = global.memoryLimit;
  points.crs = options.crs;
  points.origin = tiles.origin;
  points.quantize = !options.noQuantization;
  // Point tiles are nearly all vertex data, which our attribute encoder takes at about 2 GB/s:
  // a third of the bytes, paid for by the smaller writes at 100 M points (docs/BENCHMARKS.md).
  points.meshoptCompression = options.compress != "none";
  points.salvageTruncated = options.salvage;
  Result<std::uint32_t> attributes = parsePointAttributes(options.attributes);
  if (!attributes) return attributes.status();
  points.attributes = *attributes;
  points.resume = options.resume;
  Result<PointTilesStats> stats = writePointTiles(options.input, options.output, points);
  if (!stats) {
    sayWorkKept(options.output);
    return stats.status();
  }
  for (const std::string& warning : stats->warnings)
    fmt::print(stderr, "lodforge: warning: {}\n", warning);
  warnIfNotPlaced(global, !stats->crs.empty() || points.origin.has_value());
  say(global,
      fmt::format("wrote {}: a point tileset of {} points in {} tile{} ({} blocks, depth {}), "
                  "{} in {:.1f} s ({} points/s){}",
                  options.output, formatCount(stats->points), formatCount(stats->tiles),
                  stats->tiles == 1 ? "" : "s", formatCount(stats->blocks), stats->depth,
                  formatBytes(stats->outputBytes), stats->seconds,
                  formatCount(static_cast<std::uint64_t>(static_cast<double>(stats->points) /
                                                         std::max(stats->seconds, 1e-9))),
                  stats->crs.empty() ? "" : "; placed on Earth from its coordinate system"));
  if (stats->attributes != 0)
    detail(global, fmt::format("point attributes: {}", pointAttributeNames(stats->attributes)));
  if (stats->resumed)
    detail(global,
           fmt::format("resumed: the input as the interrupted run split it, {} of the "
                       "partition's {} nodes as it ranked them, {} tile{} as it wrote "
                       "them",
                       formatCount(stats->nodesResumed), formatCount(stats->nodes),
                       formatCount(stats->tilesResumed), stats->tilesResumed == 1 ? "" : "s"));
  if (stats->ranks > 1) reportPointRanks(global, *stats);
  return {};
}

// How a job of several ranks came by its chunks, for -v.
std::string chunkedBy(const TilesStats& stats) {
  if (stats.resumed) return "the chunks resumed";
  if (stats.readInSlices) return "the input read in slices by every rank";
  if (!stats.surface || stats.surface->rankChunks.empty()) return "the input chunked by rank 0";
  const std::vector<std::uint64_t>& chunks = stats.surface->rankChunks;
  const auto [least, most] = std::minmax_element(chunks.begin(), chunks.end());
  return fmt::format(
      "the surface's runs made by the ranks, {} to {} chunks a rank, and joined "
      "by rank 0",
      formatCount(*least), formatCount(*most));
}

void reportMeshTiles(const Global& global, const TilesCommand& options, const TilesStats& stats) {
  if (stats.surface) {
    const ReconstructStats& surface = *stats.surface;
    say(global,
        fmt::format("reconstructed {} triangles from {} points (voxel {:g}, chunks of {} voxels, "
                    "{} run{}{}{}{})",
                    formatCount(surface.triangles), formatCount(surface.points),
                    surface.grid.voxel / surface.unitScale, surface.chunkVoxels, surface.runs,
                    surface.runs == 1 ? "" : "s",
                    surface.resumedRuns > 0 ? fmt::format(", {} resumed", surface.resumedRuns) : "",
                    surface.estimatedNormals ? ", normals estimated" : "",
                    surface.droppedPieces > 0
                        ? fmt::format(", {} small pieces dropped", surface.droppedPieces)
                        : ""));
  }
  say(global,
      fmt::format("wrote {}: {} tiles ({} leaves, {} levels above them{}){}, {} in {:.1f} s ({} "
                  "input triangles/s)",
                  options.output, formatCount(stats.tiles), formatCount(stats.leaves), stats.levels,
                  stats.implicitTiling ? "; implicit tiling" : "",
                  stats.parts > 0 ? fmt::format(", {} named parts ({} in the coarsest tiles; {})",
                                                formatCount(stats.parts),
                                                formatCount(stats.partsInRoot), kPartsFileName)
                                  : "",
                  formatBytes(stats.outputBytes), stats.seconds,
                  formatCount(static_cast<std::uint64_t>(static_cast<double>(stats.inputTriangles) /
                                                         std::max(stats.seconds, 1e-9)))));
  detail(global,
         fmt::format("{} ({:.1f} s to chunks); {} threads; chunk size {:.4g}; {} triangles "
                     "after cutting; parents kept {} border vertices of {} ({:.1f} %, at most {} "
                     "in one tile) and left out {} small segments; peak memory {}",
                     stats.resumed    ? "chunks resumed"
                     : stats.streamed ? "streamed"
                                      : "loaded whole",
                     stats.chunkSeconds, stats.threads, stats.chunkSize,
                     formatCount(stats.leafTriangles), formatCount(stats.lockedVertices),
                     formatCount(stats.vertices),
                     100.0 * static_cast<double>(stats.lockedVertices) /
                         static_cast<double>(std::max<std::uint64_t>(1, stats.vertices)),
                     formatCount(stats.maxLockedVertices), formatCount(stats.droppedSegments),
                     formatBytes(peakRssBytes())));
  if (stats.takenNodes > 0)
    detail(global, fmt::format("octree: built {} nodes, took {} as the interrupted run left them",
                               formatCount(stats.builtNodes), formatCount(stats.takenNodes)));
  if (stats.ranks > 1) {
    const auto [least, most] = std::minmax_element(stats.rankWork.begin(), stats.rankWork.end());
    detail(global,
           fmt::format("{} ranks: {}; subtrees under level {}, {} to {} leaf triangles a rank, "
                       "then the levels above shared level by level; octree {:.1f} s, then the "
                       "tileset on rank 0 {:.1f} s; peak memory of rank 0 {}",
                       stats.ranks, chunkedBy(stats), stats.splitLevel, formatCount(*least),
                       formatCount(*most), stats.octreeSeconds,
                       stats.seconds - stats.chunkSeconds - stats.octreeSeconds,
                       formatBytes(peakRssBytes())));
    for (const std::string& line : stats.rankStages) detail(global, line);
  }
}

Status runMeshTiles(const Global& global, const TilesCommand& options, const TilesOptions& tiles) {
  Result<TilesStats> stats = writeTiles(options.input, options.output, tiles);
  if (!stats) {
    sayWorkKept(options.output);
    return stats.status();
  }
  if (clusterRank() != 0) return {};  // rank 0 speaks for the job
  if (stats->truncation)
    fmt::print(stderr, "lodforge: warning: {}; built from what came before\n", *stats->truncation);
  for (const std::string& warning : stats->warnings)
    fmt::print(stderr, "lodforge: warning: {}\n", warning);
  warnIfNotPlaced(global, tiles.origin.has_value() || !tiles.crs.empty());
  reportMeshTiles(global, options, *stats);
  return {};
}

bool usesSurfaceOptions(const SurfaceCommand& given) {
  const SurfaceCommand none;
  return given.orient != none.orient || given.reconstruct.voxel != none.reconstruct.voxel ||
         given.reconstruct.distance.radius != none.reconstruct.distance.radius ||
         given.reconstruct.distance.minPoints != none.reconstruct.distance.minPoints ||
         given.reconstruct.minTriangles != none.reconstruct.minTriangles;
}

// --surface: the cloud reconstructed chunk by chunk into the leaves (docs/surface.md), then
// tiled as a mesh. The CRS a LAS file names places the tileset unless --crs or --origin does.
Status runSurfaceTiles(const Global& global, const TilesCommand& options, TilesOptions tiles) {
  if (options.levels > 0)
    return Error{ErrorKind::kUsage,
                 "--levels does not go with --surface: the leaves are the reconstruction's "
                 "chunks (set their edge with --chunk-size)"};
  Result<ReconstructOptions> reconstruct = surfaceOptions(options.surfaceOptions, options.input);
  if (!reconstruct) return reconstruct.status();
  reconstruct->chunkLength = options.chunkSize;
  reconstruct->memoryLimit = global.memoryLimit;
  tiles.input.chunkSize = 0;
  tiles.surface = *reconstruct;
  if (tiles.crs.empty() && !tiles.origin) {
    Result<PointReader> reader = PointReader::open(
        options.input,
        {.batchPoints = 1, .salvageTruncated = options.salvage, .readExtras = false});
    if (reader) tiles.crs = reader->info().crs;
    tiles.crsFrom = fmt::format("the coordinate system in {}", options.input);
  }
  return runMeshTiles(global, options, tiles);
}

// Which pipeline the input and options go to, refused where they do not go together.
Status checkTilesRoute(const TilesCommand& options, bool points) {
  if (options.surface && !points)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: --surface is for point clouds (this is a mesh)", options.input)};
  if (!options.surface && usesSurfaceOptions(options.surfaceOptions))
    return Error{ErrorKind::kUsage,
                 "--voxel, --radius, --min-points, --orient and --min-triangles go with --surface"};
  return {};
}

Status runTiles(const Global& global, const TilesCommand& options) {
  Status checked = checkTilesInput(options.input);
  Result<TilesOptions> tiles =
      checked.ok() ? meshTilesOptions(global, options) : Result<TilesOptions>(checked);
  const bool points = tiles && isPointInput(options.input);
  checked = tiles ? checkTilesRoute(options, points) : tiles.status();
  // Every rank of a job checks the same: agreed, a refusal is said once (by rank 0).
  LODFORGE_TRY(agreeAcrossRanks(checked));
  if (options.surface) return runSurfaceTiles(global, options, *tiles);
  if (points) return runPointTiles(global, options, *tiles);
  return runMeshTiles(global, options, *tiles);
}

}  // namespace

void addTiles(CLI::App& app, const Global& global, Run& run) {
  auto options = std::make_shared<TilesCommand>();
  CLI::App* sub =
      app.add_subcommand("tiles", "Write a 3D Tiles 1.1 tileset of a mesh or an assembly");
  addTilesOptions(*sub, *options);
  sub->callback([&global, &run, options] {
    run = [&global, options] { return runTiles(global, *options); };
  });
}

}  // namespace lodforge::cli
