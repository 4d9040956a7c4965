#include "lodforge/tiles/tileset.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>

#include <fmt/format.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/mesh.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/io/glb_writer.h"
#include "lodforge/tiles/tileset_output.h"
#include "lodforge/tiling/chunk_grid.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

nlohmann::json boxOf(const Aabbd& bounds) {
  return {{"box", tileBox(bounds)}};
}

// After chunking: what the chunks were made from and of, so that --resume can trust them.
Status saveChunkState(const std::string& path, const nlohmann::json& identity,
                      const ChunkInput& input) {
  const ChunkGrid& grid = input.chunks->grid();
  nlohmann::json counts = nlohmann::json::array();
  for (const auto& [index, count] : input.chunks->triangleCounts())
    counts.push_back({index, count});
  const nlohmann::json state = {
      {"identity", identity},
      {"grid",
       {{"origin", {grid.origin.x, grid.origin.y, grid.origin.z}},
        {"size", grid.size},
        {"dims", grid.dims}}},
      {"bounds",
       {input.bounds.min.x, input.bounds.min.y, input.bounds.min.z, input.bounds.max.x,
        input.bounds.max.y, input.bounds.max.z}},
      {"inputTriangles", input.inputTriangles},
      {"colors", input.colors},
      {"streamed", input.streamed},
      {"frame", input.frame ? nlohmann::json(input.frame->m) : nlohmann::json()},
      {"counts", counts}};
  return OutputFile::writeWhole(path, state.dump());
}

// What identifies the input of a resumable run besides its path.
std::uint64_t fileBytes(const std::string& path) {
  Result<std::uint64_t> size = fileSize(path);
  return size ? *size : 0;
}
std::int64_t modifiedTicks(const std::string& path) {
  std::error_code error;
  const auto time = fs::last_write_time(path, error);
  return error ? 0 : static_cast<std::int64_t>(time.time_since_epoch().count());
}

std::optional<ChunkInput> resumeChunks(const std::string& path, const nlohmann::json& identity,
                                       const std::string& chunkDirectory) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    const nlohmann::json state = nlohmann::json::parse(in);
    if (state.at("identity") != identity) return std::nullopt;  // other input or options
    ChunkGrid grid;
    const auto& g = state.at("grid");
    grid.origin = {g.at("origin").at(0).get<double>(), g.at("origin").at(1).get<double>(),
                   g.at("origin").at(2).get<double>()};
    grid.size = g.at("size").get<double>();
    grid.dims = g.at("dims").get<ChunkCell>();
    std::map<std::uint64_t, std::uint64_t> counts;
    for (const auto& entry : state.at("counts"))
      counts[entry.at(0).get<std::uint64_t>()] = entry.at(1).get<std::uint64_t>();
    ChunkInput input;
    const auto& b = state.at("bounds");
    input.bounds.min = {b.at(0).get<double>(), b.at(1).get<double>(), b.at(2).get<double>()};
    input.bounds.max = {b.at(3).get<double>(), b.at(4).get<double>(), b.at(5).get<double>()};
    input.inputTriangles = state.at("inputTriangles").get<std::uint64_t>();
    input.colors = state.at("colors").get<bool>();
    input.streamed = state.at("streamed").get<bool>();
    if (!state.at("frame").is_null())
      input.frame = Mat4d{state.at("frame").get<std::array<double, 16>>()};
    input.chunks =
        std::make_unique<ChunkWriter>(ChunkWriter::reopen(grid, chunkDirectory, std::move(counts)));
    return input;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;  // damaged: chunk again
  }
}

// The memory mode and limit (§3.4) decide threads, buffers and the leaf size.
Status planMemory(const TilesOptions& options, ChunkInputOptions& input, OctreeOptions& octree) {
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  switch (options.memory) {
    case TilesMemory::kMinimal:
      octree.threads = 1;
      input.chunkBufferBytes = std::min<std::uint64_t>(input.chunkBufferBytes, 32 << 20);
      input.vertexCacheBytes = std::min<std::uint64_t>(input.vertexCacheBytes, 32 << 20);
      break;
    case TilesMemory::kModerate:
      octree.threads = options.threads > 0 ? options.threads : std::max(1, cores / 4);
      break;
    case TilesMemory::kUnbounded:
      octree.threads = options.threads > 0 ? options.threads : cores;
      input.keepInMemory = true;
      octree.keepInMemory = true;
      break;
  }
  if (options.memoryLimit > 0) {
    // The program itself (code, libraries, thread stacks, I/O buffers) takes about 32 MiB; of
    // the rest a quarter goes to the chunk buffer, an eighth to the vertex cache and half to the
    // nodes in flight (the octree lowers its parallelism to fit).
    constexpr std::uint64_t kProgram = std::uint64_t{32} << 20;
    constexpr std::uint64_t kLeast = kProgram + (std::uint64_t{16} << 20);
    if (options.memoryLimit < kLeast)
      return Error{ErrorKind::kLimit,
                   fmt::format("--memory-limit {} is too small for tiles: at least {}",
                               formatBytes(options.memoryLimit), formatBytes(kLeast))};
    const std::uint64_t usable = options.memoryLimit - kProgram;
    input.chunkBufferBytes = std::min(input.chunkBufferBytes, usable / 4);
    input.vertexCacheBytes = std::min(input.vertexCacheBytes, usable / 8);
    octree.memoryBudget = usable / 2;
    // A parent holds about four children (eight in a volume) while it is simplified, at ~200
    // bytes per triangle: smaller leaves when the budget cannot hold that for the default size.
    if (input.chunkSize == 0) {
      input.trianglesPerChunk =
          std::clamp<std::uint64_t>(octree.memoryBudget / (4 * 200), 4096, input.trianglesPerChunk);
    }
    input.keepInMemory = false;
    octree.keepInMemory = false;
  }
  input.threads = octree.threads;
  return {};
}

}  // namespace

std::array<double, 12> tileBox(const Aabbd& bounds) {
  const Vec3d c = bounds.center(), h = bounds.size() * 0.5;
  return {c.x, c.y, c.z, h.x, 0, 0, 0, h.y, 0, 0, 0, h.z};
}

std::string tileContentUri(const OctreeNode& node) {
  return fmt::format("tiles/{}-{}-{}-{}.glb", node.level, node.cell[0], node.cell[1], node.cell[2]);
}

Status writeTileContent(const MeshPart& mesh, const Aabbd& bounds, const std::string& path,
                        const TileContentOptions& options) {
  const Vec3d center = bounds.center();
  // Triangles in vertex-cache order, then vertices in first-use order (faster to draw, and what
  // the meshopt codec compresses best). The FIFO variant (Tipsify) is 2-3x faster than
  // meshopt_optimizeVertexCache, as good on scan tiles (ACMR 0.60 vs 0.63 for a 16-entry FIFO),
  // and tile writing was ~10 % of a build.
  constexpr std::size_t kCacheSize = 16;
  std::vector<std::uint32_t> indices(mesh.indices.size());
  meshopt_optimizeVertexCacheFifo(indices.data(), mesh.indices.data(), mesh.indices.size(),
                                  mesh.positions.size(), kCacheSize);
  std::vector<std::uint32_t> remap(mesh.positions.size());
  const std::size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), indices.data(),
                                                            indices.size(), mesh.positions.size());
  meshopt_remapIndexBuffer(indices.data(), indices.data(), indices.size(), remap.data());
  std::vector<Vec3f> positions(used);
  std::vector<Rgba8> colors(options.colors && !mesh.colors.empty() ? used : 0);
  std::vector<Vec3f> normals(used);
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    if (remap[v] == ~0u) continue;
    positions[remap[v]] = toFloat(mesh.positions[v] - center);
    if (!colors.empty()) colors[remap[v]] = mesh.colors[v];
    if (!mesh.normals.empty()) normals[remap[v]] = mesh.normals[v];
  }
  // The input's normals, the same in every tile that holds a vertex; from this mesh alone only
  // when there are none (which leaves shading seams along tile borders).
  if (mesh.normals.empty()) computeVertexNormals(positions, indices, normals);
  for (Vec3f& p : positions) p = toYUp(p);
  for (Vec3f& n : normals) n = toYUp(n);
  Result<GlbWriter> writer = GlbWriter::create(
      path, {.doubleSided = false, .meshoptCompression = options.meshoptCompression});
  if (!writer) return writer.status();
  Result<std::uint32_t> glbMesh =
      writer->addMesh({positions, normals, colors, indices, options.quantize}, "tile");
  if (!glbMesh) return glbMesh.status();
  writer->addNode("tile", *glbMesh);
  writer->setRootTranslation(toYUp(center));
  return writer->finish();
}

bool tileQuantized(const OctreeNode& node) {
  return node.level == 0 || tileQuantizationError(node, true) <= node.geometricError / 32;
}

double tileQuantizationError(const OctreeNode& node, bool quantize) {
  if (!quantize || node.triangles == 0) return 0;
  return 0.5 * std::sqrt(3.0) * glbQuantizationStep(node.bounds);
}

Status writeTilesetJson(const OctreeResult& octree, const std::string& path,
                        const std::optional<Mat4d>& rootTransform, bool quantized) {
  // Children come before their parents in the node list: one pass collects each subtree's
  // largest quantisation error.
  std::vector<double> quantization(octree.nodes.size(), 0.0);
  for (std::size_t i = 0; i < octree.nodes.size(); ++i) {
    const OctreeNode& node = octree.nodes[i];
    quantization[i] = tileQuantizationError(node, quantized && tileQuantized(node));
    for (std::uint32_t c : node.children)
      quantization[i] = std::max(quantization[i], quantization[c]);
  }
  // Depth first; children listed in node order.
  std::function<nlohmann::json(std::uint32_t)> tile = [&](std::uint32_t index) {
    const OctreeNode& node = octree.nodes[index];
    nlohmann::json out = {{"boundingVolume", boxOf(node.bounds)},
                          {"geometricError", node.geometricError + quantization[index]},
                          {"refine", "REPLACE"}};
    if (node.triangles > 0 && !node.meshPath.empty())
      out["content"] = {{"uri", tileContentUri(node)}};
    if (!node.children.empty()) {
      out["children"] = nlohmann::json::array();
      for (std::uint32_t c : node.children) out["children"].push_back(tile(c));
    }
    return out;
  };
  const OctreeNode& root = octree.nodes[octree.root];
  // Above the root: the error of showing nothing at all, the size of the model.
  const Vec3d size = root.bounds.size();
  const double nothing =
      std::max((root.geometricError + quantization[octree.root]) * 2, length(size));
  nlohmann::json tileset = {
      {"asset", {{"version", "1.1"}, {"generator", "lodforge " LODFORGE_VERSION}}},
      {"geometricError", nothing},
      {"root", tile(octree.root)}};
  if (rootTransform) tileset["root"]["transform"] = rootTransform->m;
  return OutputFile::writeWhole(path, tileset.dump(1) + '\n');
}

Result<TilesStats> writeTiles(const std::string& path, const std::string& outputDirectory,
                              const TilesOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  TilesStats stats;
  LODFORGE_TRY(claimTilesetOutput(path, outputDirectory));
  // One work directory with a stable name (so that an interrupted run can be resumed) holds the
  // work files and the tileset being staged; removed once the tileset is in place.
  LODFORGE_TRY(claimWorkDirectory(outputDirectory + ".work"));  // before it is ours to remove
  ScopedDirectory work{outputDirectory + ".work"};
  ScopedDirectory staging{work.path + "/tileset"};
  std::error_code error;
  if (!options.resume) {
    fs::remove_all(staging.path, error);
    fs::remove_all(work.path + "/nodes", error);
    fs::remove(work.path + "/state.json", error);
  }
  fs::create_directories(fs::path(staging.path) / "tiles", error);
  if (!error) fs::create_directories(fs::path(work.path) / "nodes", error);
  if (error) return ioError(work.path, fmt::format("cannot create: {}", error.message()));
  // On failure or Ctrl-C after the chunks are complete, the work directory stays for --resume;
  // otherwise (bad input, or success) it goes.
  struct KeepOnFailure {
    ScopedDirectory& staging;
    ScopedDirectory& work;
    bool done = false;
    ~KeepOnFailure() {
      std::error_code ignored;
      if (!done && fs::exists(work.path + "/state.json", ignored))
        staging.path.clear(), work.path.clear();
    }
  } keep{staging, work};

  ChunkInputOptions input = options.input;
  OctreeOptions octree = options.octree;
  input.levels = octree.levels;
  LODFORGE_TRY(planMemory(options, input, octree));
  stats.threads = octree.threads;

  // Georeferencing: a CRS is set up on the first input point (the local frame's origin).
  struct LazyCrs {
    std::string crs;
    std::optional<CrsToLocal> transform;
    Status error;
  };
  auto lazy = std::make_shared<LazyCrs>(LazyCrs{options.crs, std::nullopt, {}});
  if (!options.crs.empty()) {
    input.transform = [lazy](Vec3d in, Vec3d& out) {
      if (!lazy->transform) {
        Result<CrsToLocal> created = CrsToLocal::create(lazy->crs, in);
        if (!created) {
          lazy->error = created.status();
          return false;
        }
        lazy->transform = std::move(*created);
      }
      return lazy->transform->apply(in, out);
    };
  }

  // Stream the input into the chunk grid, or take the chunks of an interrupted run.
  input.workDirectory = work.path;
  const std::string statePath = work.path + "/state.json";
  const nlohmann::json identity = {
      {"workFormat", 2},  // 2: indexed chunk blocks; work files of another format start over
      {"input", fs::absolute(path, error).string()},
      {"bytes", fileBytes(path)},
      {"modified", modifiedTicks(path)},
      {"chunkSize", input.chunkSize},
      {"trianglesPerChunk", input.trianglesPerChunk},
      {"levels", input.levels},
      {"salvage", input.salvageTruncated},
      {"keep", octree.keep},
      {"maxNormalDeviation", octree.maxNormalDeviationDegrees},
      {"errorSamples", octree.errorSamples},
      {"crs", options.crs},
      {"meshopt", options.meshoptCompression},
      {"quantize", options.quantize},
      {"origin", options.origin ? fmt::format("{},{},{}", options.origin->longitude,
                                              options.origin->latitude, options.origin->height)
                                : ""}};
  std::optional<ChunkInput> chunked;
  if (options.resume) chunked = resumeChunks(statePath, identity, work.path + "/chunks");
  if (chunked) {
    stats.resumed = true;
  } else {
    fs::remove_all(work.path + "/nodes", error);
    fs::remove_all(fs::path(staging.path) / "tiles", error);
    fs::create_directories(fs::path(staging.path) / "tiles", error);
    if (!error) fs::create_directories(work.path + "/nodes", error);
    if (error) return ioError(work.path, fmt::format("cannot create: {}", error.message()));
    Result<ChunkInput> fresh = chunkInput(path, input);
    if (!fresh) return lazy->error.ok() ? fresh.status() : lazy->error;
    chunked = std::move(*fresh);
    if (options.origin) chunked->frame = eastNorthUpToEcef(*options.origin);
    if (lazy->transform) chunked->frame = lazy->transform->localToEcef();
    if (!input.keepInMemory) LODFORGE_TRY(saveChunkState(statePath, identity, *chunked));
  }
  octree.resume = stats.resumed;
  stats.inputTriangles = chunked->inputTriangles;
  stats.truncation = chunked->truncation;
  stats.streamed = chunked->streamed;
  stats.chunkSize = chunked->chunks->grid().size;
  stats.leafTriangles = chunked->chunks->triangleCount();
  stats.chunkSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const bool colors = chunked->colors;
  const ChunkWriter& chunks = *chunked->chunks;

  // The octree, each tile written as soon as it is built.
  octree.workDirectory = work.path + "/nodes";
  const std::string tilesDirectory = staging.path;
  Result<OctreeResult> tree =
      buildOctree(chunks, octree, [&](const OctreeNode& node, const MeshPart& mesh) -> Status {
        if (mesh.triangleCount() == 0) return {};
        return writeTileContent(mesh, node.bounds, tilesDirectory + "/" + tileContentUri(node),
                                {.colors = colors,
                                 .meshoptCompression = options.meshoptCompression,
                                 .quantize = options.quantize && tileQuantized(node)});
      });
  if (!tree) return tree.status();
  LODFORGE_TRY(
      writeTilesetJson(*tree, staging.path + "/tileset.json", chunked->frame, options.quantize));
  for (const OctreeNode& node : tree->nodes) {
    stats.tiles += node.triangles > 0 ? 1 : 0;
    stats.leaves += node.level == 0 ? 1 : 0;
    if (node.level > 0) {
      stats.lockedVertices += node.lockedVertices;
      stats.vertices += node.vertices;
      stats.droppedSegments += node.droppedSegments;
      stats.maxLockedVertices = std::max(stats.maxLockedVertices, node.lockedVertices);
    }
  }
  stats.levels = tree->levels;
  stats.outputBytes = directoryBytes(staging.path);

  // Complete: replace the previous tileset, if any, by the new one.
  keep.done = true;
  LODFORGE_TRY(replaceDirectory(staging, outputDirectory));
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace lodforge
