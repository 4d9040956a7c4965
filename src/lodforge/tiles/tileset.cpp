#include "lodforge/tiles/tileset.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/cluster.h"
#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/output_claim.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/tiles/point_resume.h"
#include "lodforge/tiles/surface_input.h"
#include "lodforge/tiles/tile_texture.h"
#include "lodforge/tiles/tileset_output.h"
#include "lodforge/tiles/tileset_parts.h"
#include "lodforge/tiling/chunk_ply.h"
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
  explicit WorkPlace(const std::string& workDirectory)
      : work(workDirectory), staging(workDirectory + "/tileset") {}
  ScopedDirectory work;
  ScopedDirectory staging;
  bool done = false;
  ~WorkPlace() {
    std::error_code ignored;
    if (!done && tilesWorkKept(work.path)) staging.path.clear(), work.path.clear();
  }
};

// Empties what a run makes again (all of it unless resuming) and creates the folders. A resumed
// run removes the temporaries a killed one left in the staged tileset.
Status prepareWorkPlace(const WorkPlace& place, bool keepEarlierWork) {
  std::error_code error;
  if (keepEarlierWork) removeOutputTemporaries(place.staging.path);
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
  // 4: chunks may be in pieces by rank; work files of another format start over.
  return {{"workFormat", 4},
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
// In a job of several ranks, each node built counts towards the job's progress.
Result<OctreeResult> buildTiles(const ChunkInput& chunked, const TilesOptions& options,
                                const OctreeOptions& octree, const std::string& tilesetDirectory,
                                const TileTexturing* texturing, std::uint64_t& builtNodes,
                                std::uint64_t doneBefore = 0) {
  std::atomic<std::uint64_t> built = 0;
  const auto counted = [&](Result<OctreeResult> tree) {
    builtNodes += built;
    return tree;
  };
  return counted(buildOctree(
      *chunked.chunks, octree, [&](const OctreeNode& node, const MeshPart& mesh) -> Status {
        reportProgress("nodes", doneBefore + ++built);
        if (mesh.triangleCount() == 0) return {};
        return writeTileContent(mesh, node.bounds, tilesetDirectory + "/" + tileContentUri(node),
                                {.colors = chunked.colors,
                                 .meshoptCompression = options.meshoptCompression,
                                 .quantize = options.quantize && tileQuantized(node),
                                 .parts = &chunked.parts,
                                 .texturing = texturing,
                                 .level = static_cast<std::uint32_t>(node.level)});
      }));
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

// The nodes the octree builds (not the empty root above the top level that --levels may leave).
std::uint64_t plannedNodes(const OctreeResult& tree) {
  return static_cast<std::uint64_t>(
      std::count_if(tree.nodes.begin(), tree.nodes.end(),
                    [&](const OctreeNode& node) { return node.level <= tree.levels; }));
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

// The chunk input's and the octree's options for this run, memory planned; a CRS attached.
struct RunPlan {
  ChunkInputOptions input;
  OctreeOptions octree;
  std::shared_ptr<const LazyCrs> crs;
};
Result<RunPlan> planRun(const TilesOptions& options, const std::string& workDirectory) {
  RunPlan run{options.input, options.octree, nullptr};
  run.input.levels = run.octree.levels;
  run.input.workDirectory = workDirectory;
  run.octree.workDirectory = workDirectory + "/nodes";
  LODFORGE_TRY(
      planTilesMemory(options.memory, options.memoryLimit, options.threads, run.input, run.octree));
  if (clustered()) {
    // Ranks hand chunks and node meshes over through the work directory.
    run.input.keepInMemory = false;
    run.octree.keepInMemory = false;
  }
  run.crs = attachCrs(options.crs, options.crsFrom, run.input);
  return run;
}

// The chunks in the work directory, when they are complete, intact and of the same input and
// options (an interrupted run's, or rank 0's for the other ranks of a job).
std::optional<ChunkInput> chunksInWork(const std::string& path, const TilesOptions& options,
                                       const RunPlan& run) {
  const std::string& work = run.input.workDirectory;
  return resumeChunks(workStatePath(work), runIdentity(path, options, run.input, run.octree),
                      work + "/chunks");
}

// The chunks of an interrupted run, when resuming.
std::optional<ChunkInput> earlierChunks(const std::string& path, const TilesOptions& options,
                                        const RunPlan& run) {
  if (!options.resume) return std::nullopt;
  return chunksInWork(path, options, run);
}

// Chunks just made: placed on Earth, and recorded for --resume.
Status recordChunks(const std::string& path, const TilesOptions& options, const RunPlan& run,
                    ChunkInput& chunks) {
  if (options.origin) chunks.frame = eastNorthUpToEcef(*options.origin);
  if (run.crs->transform) chunks.frame = run.crs->transform->localToEcef();
  if (run.input.keepInMemory) return {};
  return saveChunkState(workStatePath(run.input.workDirectory),
                        runIdentity(path, options, run.input, run.octree), chunks);
}

// Streams the input into the chunk grid (a fresh work place).
Result<ChunkInput> chunkFresh(const std::string& path, const TilesOptions& options,
                              const RunPlan& run, const WorkPlace& place,
                              std::optional<ReconstructStats>& surface) {
  LODFORGE_TRY(prepareWorkPlace(place, false));
  Result<ChunkInput> fresh =
      options.surface ? surfaceChunkInput(path, run.input, resumableSurface(options, run.input),
                                          surface.emplace())
                      : chunkInput(path, run.input);
  if (!fresh) return run.crs->error.ok() ? fresh.status() : run.crs->error;
  LODFORGE_TRY(recordChunks(path, options, run, *fresh));
  return fresh;
}

// Streams the input into the chunk grid, or takes the chunks of an interrupted run.
Result<ChunkInput> chunkOrResume(const std::string& path, const TilesOptions& options,
                                 const RunPlan& run, const WorkPlace& place, bool& resumed,
                                 std::optional<ReconstructStats>& surface) {
  std::optional<ChunkInput> earlier = earlierChunks(path, options, run);
  resumed = earlier.has_value();
  if (earlier) return std::move(*earlier);
  return chunkFresh(path, options, run, place, surface);
}

// A textured input's pyramids and what its tiles bake from (no `tiles`: untextured).
struct Texturing {
  std::optional<TexturePyramid> pyramid;
  std::optional<TileTexturing> tiles;
};
Status prepareTexturing(const ChunkInput& chunked, const TilesOptions& options,
                        const OctreeOptions& octree, const std::string& workDirectory, bool resumed,
                        Texturing& out) {
  const TexturePlan plan = planTextureMemory(options.memoryLimit, octree.threads,
                                             options.atlas.maxSize, options.textureCacheBytes);
  Result<std::optional<TexturePyramid>> pyramid =
      buildPyramids(chunked, workDirectory, plan, resumed);
  if (!pyramid) return pyramid.status();
  if (!*pyramid) return {};
  out.pyramid = std::move(**pyramid);
  AtlasOptions atlas = options.atlas;
  atlas.maxSize = plan.pageSide;
  out.tiles = TileTexturing{&chunked.textures, &*out.pyramid, atlas, options.textureEncoding};
  return {};
}

// The listing (explicit or implicit) and parts.json beside the staged contents, the counts,
// then the staged tileset replaces the output.
Status finishTileset(const OctreeResult& tree, const ChunkInput& chunked,
                     const TilesOptions& options, WorkPlace& place,
                     const std::string& outputDirectory, TilesStats& stats) {
  const std::string partsUri = chunked.parts.empty() ? "" : kPartsFileName;
  Result<bool> implicit = implicitTilingWanted(options.implicitTiling, tree);
  if (!implicit) return implicit.status();
  stats.implicitTiling = *implicit;
  // Contents are written under their explicit names: moved when implicit, or back where an
  // interrupted implicit attempt moved them.
  if (*implicit || stats.resumed) LODFORGE_TRY(placeContents(tree, place.staging.path, *implicit));
  if (*implicit)
    LODFORGE_TRY(writeImplicitTileset(tree, chunked.chunks->grid(), place.staging.path,
                                      chunked.frame, options.quantize, partsUri,
                                      options.subtreeLevels));
  else
    LODFORGE_TRY(writeTilesetJson(tree, place.staging.path + "/tileset.json", chunked.frame,
                                  options.quantize, partsUri));
  if (!partsUri.empty())
    LODFORGE_TRY(writePartsJson(tree, chunked.parts, place.staging.path + "/" + partsUri));
  countTiles(tree, stats);
  stats.outputBytes = directoryBytes(place.staging.path);
  place.done = true;
  return replaceDirectory(place.staging, outputDirectory);
}

// The output and its work directory claimed and locked, the work place made ready.
Status claimWorkPlace(const std::string& path, const std::string& outputDirectory,
                      const TilesOptions& options, std::optional<WorkPlace>& place,
                      WorkLock& lock) {
  LODFORGE_TRY(claimTilesetOutput(path, outputDirectory));
  const std::string workDirectory = tilesWorkDirectory(outputDirectory);
  LODFORGE_TRY(claimWorkDirectory(workDirectory));  // before it is ours to remove
  Result<WorkLock> locked = lockWorkDirectory(workDirectory);
  if (!locked) return locked.status();
  lock = std::move(*locked);
  place.emplace(workDirectory);
  return prepareWorkPlace(*place, options.resume);
}

// A job of several ranks (docs/distributed.md): rank 0 claims the output and chunks the input
// while the others wait; every rank builds its share of the octree's subtrees; rank 0 builds
// the levels above them and writes the tileset. Each step ends with every rank's outcome.
class RankedTiles {
 public:
  RankedTiles(const std::string& path, const std::string& outputDirectory,
              const TilesOptions& options)
      : path_(path), output_(outputDirectory), options_(options), lead_(clusterRank() == 0) {}

  Result<TilesStats> run() {
    Result<RunPlan> run = planRun(options_, tilesWorkDirectory(output_));
    LODFORGE_TRY(agreeAcrossRanks(lead_ && run ? claimOnLead(*run) : run.status()));
    setActivityDirectory(run->input.workDirectory + "/ranks");
    LODFORGE_TRY(chunkTogether(*run));
    stats_.chunkSeconds = secondsSince(start_);
    recordStage("chunks");
    countChunks(*chunked_, stats_);
    stats_.threads = run->octree.threads;
    stats_.ranks = clusterSize();
    Result<std::uint64_t> taken = buildShare(run->octree);
    if (!taken) return taken.status();
    Result<std::uint64_t> built = sumAcrossRanks(builtNodes_);
    if (!built) return built.status();
    builtNodes_ = 0;
    stats_.octreeSeconds = secondsSince(start_) - stats_.chunkSeconds;
    recordStage("octree");
    LODFORGE_TRY(agreeAcrossRanks(lead_ ? writeTileset(run->octree) : Status{}));
    stats_.rankStages = rankStages();
    stats_.builtNodes = *built + builtNodes_;  // and rank 0's since the sum (none)
    stats_.takenNodes = *taken;
    stats_.seconds = secondsSince(start_);
    return stats_;
  }

 private:
  // Rank 0 claims the output and its work directory, and takes an interrupted job's chunks
  // when resuming (a fresh work place otherwise).
  Status claimOnLead(const RunPlan& run) {
    LODFORGE_TRY(claimWorkPlace(path_, output_, options_, place_, lock_));
    std::optional<ChunkInput> earlier = earlierChunks(path_, options_, run);
    stats_.resumed = earlier.has_value();
    if (!earlier) return prepareWorkPlace(*place_, false);
    chunked_ = std::move(*earlier);
    return prepareTexturing(*chunked_, options_, run.octree, place_->work.path, true, texturing_);
  }

  // The chunks on every rank: an interrupted job's; or the input read in slices by every rank
  // where it allows that; or chunked by rank 0 while the others wait. The others then take
  // rank 0's.
  Status chunkTogether(const RunPlan& run) {
    Result<std::uint64_t> resumed = sumAcrossRanks(stats_.resumed ? 1 : 0);
    if (!resumed) return resumed.status();
    jobResumed_ = *resumed > 0;  // rank 0's decision, for every rank
    if (!jobResumed_) {
      Result<bool> sliced = readInSlices(run);
      if (!sliced) return sliced.status();
      if (!*sliced && options_.surface) LODFORGE_TRY(surfaceTogether(run));
      if (!*sliced && !options_.surface) {
        reportActivity(lead_ ? "chunking the input" : "waiting for rank 0 to chunk the input");
        LODFORGE_TRY(agreeAcrossRanks(lead_ ? chunkOnLead(run) : Status{}));
      }
    }
    return agreeAcrossRanks(chunked_ ? Status{} : takeChunks(run));
  }

  // Every rank reads its slice of a PLY that allows it (chunk_ply.h). False where it does not,
  // or where its faces turn out to be of different sizes: then rank 0 chunks it alone.
  Result<bool> readInSlices(const RunPlan& run) {
    if (options_.surface || fileExtension(path_) != "ply") return false;
    Result<std::uint64_t> faces = plyFacesInSlices(path_, run.input);
    // Every rank must decide the same: each sees what the others count.
    Result<std::uint64_t> total = sumAcrossRanks(faces ? *faces : 0);
    if (!total) return total.status();
    const auto ranks = static_cast<std::uint64_t>(clusterSize());
    LODFORGE_TRY(agreeAcrossRanks(!faces ? faces.status()
                                  : *total != *faces * ranks
                                      ? Status(badInput(path_,
                                                        "the ranks read different files "
                                                        "by this name (is it on a file "
                                                        "system every rank shares?)"))
                                      : Status()));
    if (*faces == 0) return false;
    reportActivity("reading its slice of the input into chunks");
    Result<ChunkInput> chunks = [&] {
      const JobProgress progress(fmt::format("tiles: chunks, {} ranks", clusterSize()), "faces",
                                 *faces);
      return chunkPlyInSlices(path_, run.input);
    }();
    if (!chunks && chunks.status().kind() == ErrorKind::kUnsupported) return false;
    if (!chunks) return chunks.status();
    chunked_ = std::move(*chunks);
    LODFORGE_TRY(
        agreeAcrossRanks(lead_ ? recordChunks(path_, options_, run, *chunked_) : Status{}));
    stats_.readInSlices = true;
    return true;
  }

  // A surface: every rank makes its share of the reconstruction's runs and rank 0 joins them into
  // the chunks (surface_input.h).
  Status surfaceTogether(const RunPlan& run) {
    ReconstructOptions surface = resumableSurface(options_, run.input);
    surface.acrossRanks = true;
    Result<ChunkInput> chunks =
        surfaceChunkInput(path_, run.input, surface, stats_.surface.emplace());
    Status finished = chunks ? Status{} : run.crs->error.ok() ? chunks.status() : run.crs->error;
    if (lead_ && chunks) {
      chunked_ = std::move(*chunks);
      finished = recordChunks(path_, options_, run, *chunked_);
      if (finished.ok())
        finished =
            prepareTexturing(*chunked_, options_, run.octree, place_->work.path, false, texturing_);
    }
    return agreeAcrossRanks(finished);
  }

  // Rank 0 alone: the input chunked, a textured input's pyramids made.
  Status chunkOnLead(const RunPlan& run) {
    Result<ChunkInput> chunks = chunkFresh(path_, options_, run, *place_, stats_.surface);
    if (!chunks) return chunks.status();
    chunked_ = std::move(*chunks);
    return prepareTexturing(*chunked_, options_, run.octree, place_->work.path, false, texturing_);
  }

  // The other ranks take rank 0's chunks and pyramids, as a resumed run would.
  Status takeChunks(const RunPlan& run) {
    const std::string& workDirectory = run.input.workDirectory;
    std::optional<ChunkInput> chunks = chunksInWork(path_, options_, run);
    if (!chunks)
      return Error{ErrorKind::kIo,
                   fmt::format("{}: cannot read the chunks rank 0 made (is {} on a file system "
                               "every rank shares, and the input the same file for each?)",
                               describeRank(), workDirectory)};
    chunked_ = std::move(*chunks);
    return prepareTexturing(*chunked_, options_, run.octree, workDirectory, true, texturing_);
  }

  // Every rank its nodes, round by round: its subtrees, then its nodes of each level above them
  // (what an interrupted job finished is taken); the job's progress on rank 0. Returns how many
  // nodes all ranks took from an interrupted job.
  Result<std::uint64_t> buildShare(const OctreeOptions& octree) {
    OctreeOptions share = octree;
    share.rank = clusterRank();
    share.ranks = clusterSize();
    share.quiet = true;
    const ShareCounts counts = countShare(*chunked_->chunks, share);
    const JobProgress progress(fmt::format("tiles: octree, {} ranks", share.ranks), "nodes",
                               counts.nodes);
    std::uint64_t done = 0, taken = 0;
    for (int round = 0; round < counts.rounds; ++round) {
      const std::uint64_t mine = counts.mine[static_cast<std::size_t>(round)];
      share.round = round;
      // Later rounds take the earlier ones' nodes; the first, an interrupted job's.
      share.resume = round > 0 || jobResumed_;
      reportActivity(fmt::format("building its {} nodes of round {} of {} of the octree", mine,
                                 round + 1, counts.rounds));
      const std::uint64_t before = builtNodes_;
      Result<OctreeResult> tree =
          buildTiles(*chunked_, options_, share, staging(), texturing(), builtNodes_, done);
      done += mine;
      taken += mine - (builtNodes_ - before);
      reportProgress("nodes", done);
      LODFORGE_TRY(agreeAcrossRanks(tree.status()));
      if (round == 0) stats_.splitLevel = tree->splitLevel, stats_.rankWork = tree->rankWork;
    }
    reportActivity("done with its nodes");
    return sumAcrossRanks(taken);
  }

  // Rank 0, once every node is built: the tree gathered from their summaries, the tileset.
  Status writeTileset(const OctreeOptions& octree) {
    reportActivity("writing the tileset");
    OctreeOptions all = octree;
    all.resume = true;        // takes every node
    std::uint64_t built = 0;  // none (a root without content above --levels is no node)
    Result<OctreeResult> tree = buildTiles(*chunked_, options_, all, staging(), texturing(), built);
    if (!tree) return tree.status();
    builtNodes_ += built;
    LODFORGE_TRY(finishTileset(*tree, *chunked_, options_, *place_, output_, stats_));
    recordStage("tileset");
    return {};
  }

  std::string staging() const { return tilesWorkDirectory(output_) + "/tileset"; }
  const TileTexturing* texturing() const { return texturing_.tiles ? &*texturing_.tiles : nullptr; }

  const std::string& path_;
  const std::string& output_;
  const TilesOptions& options_;
  const bool lead_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  TilesStats stats_;
  WorkLock lock_;  // rank 0's; released after the work place is cleaned up
  std::optional<WorkPlace> place_;
  std::optional<ChunkInput> chunked_;
  Texturing texturing_;  // points into chunked_
  std::uint64_t builtNodes_ = 0;
  bool jobResumed_ = false;  // rank 0 took an interrupted job's chunks
};

}  // namespace

bool tilesWorkKept(const std::string& workDirectory) {
  std::error_code ignored;
  return fs::exists(workStatePath(workDirectory), ignored) || surfaceWorkKept(workDirectory) ||
         pointWorkKept(workDirectory + "/points");  // pointWorkDirectory
}

std::string tilesWorkDirectory(const std::string& outputDirectory) {
  return outputDirectory + ".work";
}

Result<TilesStats> writeTiles(const std::string& path, const std::string& outputDirectory,
                              const TilesOptions& options) {
  if (clustered()) return RankedTiles(path, outputDirectory, options).run();
  const auto start = std::chrono::steady_clock::now();
  TilesStats stats;
  WorkLock lock;  // released after the work place is cleaned up
  std::optional<WorkPlace> place;
  LODFORGE_TRY(claimWorkPlace(path, outputDirectory, options, place, lock));
  Result<RunPlan> run = planRun(options, place->work.path);
  if (!run) return run.status();
  stats.threads = run->octree.threads;

  Result<ChunkInput> chunked =
      chunkOrResume(path, options, *run, *place, stats.resumed, stats.surface);
  if (!chunked) return chunked.status();
  countChunks(*chunked, stats);
  stats.chunkSeconds = secondsSince(start);

  run->octree.resume = stats.resumed;
  Texturing texturing;
  LODFORGE_TRY(
      prepareTexturing(*chunked, options, run->octree, place->work.path, stats.resumed, texturing));
  Result<OctreeResult> tree =
      buildTiles(*chunked, options, run->octree, place->staging.path,
                 texturing.tiles ? &*texturing.tiles : nullptr, stats.builtNodes);
  if (!tree) return tree.status();
  stats.takenNodes = plannedNodes(*tree) - stats.builtNodes;
  LODFORGE_TRY(finishTileset(*tree, *chunked, options, *place, outputDirectory, stats));
  stats.seconds = secondsSince(start);
  return stats;
}

}  // namespace lodforge
