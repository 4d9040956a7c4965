#include "lodforge/tiles/tileset.h"

#include <unistd.h>
#include <chrono>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/mesh.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/glb_writer.h"
#include "lodforge/io/model_io.h"
#include "lodforge/tiling/chunk_grid.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

// glTF is y-up, 3D Tiles z-up: a viewer turns content (x, y, z) into (x, -z, y).
Vec3f toYUp(Vec3f p) {
  return {p.x, p.z, -p.y};
}
Vec3d toYUp(Vec3d p) {
  return {p.x, p.z, -p.y};
}

nlohmann::json boxOf(const Aabbd& bounds) {
  const Vec3d c = bounds.center(), h = bounds.size() * 0.5;
  return {{"box", {c.x, c.y, c.z, h.x, 0, 0, 0, h.y, 0, 0, 0, h.z}}};
}

// A directory removed when this goes out of scope (work files, an unfinished output).
struct ScopedDirectory {
  std::string path;
  ~ScopedDirectory() {
    std::error_code ignored;
    if (!path.empty()) fs::remove_all(path, ignored);
  }
};

}  // namespace

std::string tileContentUri(const OctreeNode& node) {
  return fmt::format("tiles/{}-{}-{}-{}.glb", node.level, node.cell[0], node.cell[1], node.cell[2]);
}

Status writeTileContent(const MeshPart& mesh, const Aabbd& bounds, const std::string& path) {
  const Vec3d center = bounds.center();
  std::vector<Vec3f> positions(mesh.positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i)
    positions[i] = toFloat(mesh.positions[i] - center);
  std::vector<Vec3f> normals(positions.size());
  computeVertexNormals(positions, mesh.indices, normals);
  for (Vec3f& p : positions) p = toYUp(p);
  for (Vec3f& n : normals) n = toYUp(n);
  Result<GlbWriter> writer = GlbWriter::create(path, {.doubleSided = false});
  if (!writer) return writer.status();
  Result<std::uint32_t> glbMesh =
      writer->addMesh({positions, normals, mesh.colors, mesh.indices}, "tile");
  if (!glbMesh) return glbMesh.status();
  writer->addNode("tile", *glbMesh);
  writer->setRootTranslation(toYUp(center));
  return writer->finish();
}

Status writeTilesetJson(const OctreeResult& octree, const std::string& path) {
  // Depth first; children listed in node order.
  std::function<nlohmann::json(std::uint32_t)> tile = [&](std::uint32_t index) {
    const OctreeNode& node = octree.nodes[index];
    nlohmann::json out = {{"boundingVolume", boxOf(node.bounds)},
                          {"geometricError", node.geometricError},
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
  const double nothing = std::max(root.geometricError * 2, length(size));
  const nlohmann::json tileset = {
      {"asset", {{"version", "1.1"}, {"generator", "lodforge " LODFORGE_VERSION}}},
      {"geometricError", nothing},
      {"root", tile(octree.root)}};
  std::ofstream out(path);
  if (!out) return ioError(path, "cannot create");
  out << tileset.dump(1) << '\n';
  if (!out.flush()) return ioError(path, "cannot write");
  return {};
}

Result<TilesStats> writeTiles(const std::string& input, const std::string& outputDirectory,
                              const TilesOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  TilesStats stats;
  std::error_code error;
  if (fs::exists(outputDirectory) && !fs::exists(fs::path(outputDirectory) / "tileset.json") &&
      !fs::is_empty(outputDirectory, error)) {
    return Error{
        ErrorKind::kUsage,
        fmt::format("{}: exists and is not a tileset; not overwriting it", outputDirectory)};
  }
  const std::string suffix = fmt::format(".tmp-{}", ::getpid());
  ScopedDirectory staging{outputDirectory + suffix};
  ScopedDirectory work{outputDirectory + ".work" + suffix};
  fs::create_directories(fs::path(staging.path) / "tiles");
  fs::create_directories(fs::path(work.path) / "nodes");

  // Read, then cut into the chunk grid on disk.
  Result<Model> model = readModel(input);
  if (!model) return model.status();
  stats.inputTriangles = model->triangleCount();
  if (stats.inputTriangles == 0) return badInput(input, "the model has no triangles");
  const Aabb local = model->bounds();
  Aabbd bounds;
  bounds.add(model->origin + toDouble(local.min));
  bounds.add(model->origin + toDouble(local.max));
  stats.chunkSize = options.chunkSize > 0 ? options.chunkSize
                                          : ChunkGrid::sizeFor(bounds, stats.inputTriangles,
                                                               options.trianglesPerLeaf);
  ChunkWriter chunks(ChunkGrid::over(bounds, stats.chunkSize), work.path + "/chunks",
                     options.chunkBufferBytes);
  {
    Progress progress("tiles: chunks", stats.inputTriangles);
    std::vector<ChunkCell> cells;
    std::vector<CutCorner> corners;
    const bool colors = model->hasColors();
    for (std::size_t o = 0; o < model->objectCount(); ++o) {
      const ObjectRecord& object = model->objects[o];
      const auto positions = model->objectPositions(o);
      const auto indices = model->objectIndices(o);
      for (std::size_t t = 0; t < indices.size(); t += 3) {
        std::array<CutCorner, 3> triangle;
        for (std::size_t k = 0; k < 3; ++k) {
          const std::uint32_t v = indices[t + k];
          triangle[k].position = model->origin + toDouble(positions[v]);
          triangle[k].color =
              colors ? model->colors[object.vertexOffset + v] : Rgba8{255, 255, 255, 255};
        }
        cells.clear();
        corners.clear();
        cutTriangle(chunks.grid(), triangle, cells, corners);
        for (std::size_t p = 0; p < cells.size(); ++p)
          LODFORGE_TRY(
              chunks.add(cells[p], std::span<const CutCorner, 3>(corners.data() + 3 * p, 3)));
        if (t % (3 * 65536) == 0) {
          LODFORGE_TRY(checkCancelled());
          progress.advance(std::min<std::uint64_t>(65536, (indices.size() - t) / 3));
        }
      }
    }
    LODFORGE_TRY(chunks.flush());
    progress.finish();
  }
  stats.leafTriangles = chunks.triangleCount();
  const bool colors = model->hasColors();
  model = Model{};  // the chunks hold it now

  // The octree, each tile written as soon as it is built.
  OctreeOptions octree = options.octree;
  octree.workDirectory = work.path + "/nodes";
  const std::string tilesDirectory = staging.path;
  Result<OctreeResult> tree =
      buildOctree(chunks, octree, [&](const OctreeNode& node, const MeshPart& mesh) -> Status {
        if (mesh.triangleCount() == 0) return {};
        MeshPart content = mesh;
        if (!colors) content.colors.clear();
        return writeTileContent(content, node.bounds, tilesDirectory + "/" + tileContentUri(node));
      });
  if (!tree) return tree.status();
  LODFORGE_TRY(writeTilesetJson(*tree, staging.path + "/tileset.json"));
  for (const OctreeNode& node : tree->nodes) {
    stats.tiles += node.triangles > 0 ? 1 : 0;
    stats.leaves += node.level == 0 ? 1 : 0;
  }
  stats.levels = tree->levels;
  for (const auto& entry : fs::recursive_directory_iterator(staging.path))
    if (entry.is_regular_file()) stats.outputBytes += entry.file_size();

  // Complete: replace the previous tileset, if any, by the new one.
  if (fs::exists(outputDirectory)) {
    const std::string old = outputDirectory + ".old" + suffix;
    fs::rename(outputDirectory, old, error);
    if (error) return ioError(outputDirectory, error.message());
    ScopedDirectory removeOld{old};
  }
  fs::rename(staging.path, outputDirectory, error);
  if (error) return ioError(outputDirectory, error.message());
  staging.path.clear();
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace lodforge
