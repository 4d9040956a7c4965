// How honest and how tight a mesh tileset's geometric errors are (issue 38), measured from the
// tileset alone: bench_tile_error [--samples N] TILESET_DIR...
// Under REPLACE refinement the full-resolution surface a tile stands for is the union of the
// leaf contents under it. For every tile with content and children, the symmetric Hausdorff
// distance between its content and that union is measured by dense sampling (N area-uniform
// points on each side plus every triangle's corner, exact point-to-triangle distances) and
// compared with its declared geometricError, per level of the tree.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/distance.h"
#include "lodforge/io/mesh/gltf_reader.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

// A mesh in one frame for the whole tileset: positions relative to the first content's origin.
struct Mesh {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
};

struct Tile {
  int depth = 0;
  double declared = 0;
  std::string uri;  // empty: no content
  std::vector<std::size_t> children;
};

struct Tileset {
  fs::path directory;
  std::vector<Tile> tiles;  // tiles[0] is the root
  bool haveFrame = false;
  Vec3d frame;  // the shared origin
};

std::size_t addTile(const nlohmann::json& json, int depth, Tileset& set) {
  const std::size_t index = set.tiles.size();
  set.tiles.push_back({depth,
                       json.at("geometricError").get<double>(),
                       json.contains("content") ? json["content"]["uri"].get<std::string>() : "",
                       {}});
  for (const auto& child : json.value("children", nlohmann::json::array())) {
    const std::size_t c = addTile(child, depth + 1, set);
    set.tiles[index].children.push_back(c);
  }
  return index;
}

void appendContent(Tileset& set, const std::string& uri, Mesh& out) {
  Result<Model> model = readGltf((set.directory / uri).string());
  if (!model) {
    fmt::print(stderr, "{}: {}\n", uri, model.error().message);
    std::exit(1);
  }
  if (!set.haveFrame) {
    set.frame = model->origin;
    set.haveFrame = true;
  }
  const Vec3d shift = model->origin - set.frame;
  const auto base = static_cast<std::uint32_t>(out.positions.size());
  for (const Vec3f& p : model->positions) out.positions.push_back(toFloat(toDouble(p) + shift));
  for (const ObjectRecord& o : model->objects) {
    for (std::uint32_t k = 0; k < 3 * o.triangleCount; ++k)
      out.indices.push_back(base + o.vertexOffset + model->indices[3 * o.triangleOffset + k]);
  }
}

void appendLeaves(Tileset& set, std::size_t tile, Mesh& out) {
  if (set.tiles[tile].children.empty()) {
    if (!set.tiles[tile].uri.empty()) appendContent(set, set.tiles[tile].uri, out);
    return;
  }
  for (std::size_t c : set.tiles[tile].children) appendLeaves(set, c, out);
}

struct LevelStats {
  std::vector<double> ratios;  // measured / declared
  std::size_t under = 0;       // measured above declared
  std::size_t notMonotonic = 0;
};

void measure(const fs::path& directory, std::uint32_t samples) {
  std::ifstream in(directory / "tileset.json");
  const nlohmann::json json = nlohmann::json::parse(in);
  Tileset set{directory, {}, false, {}};
  addTile(json.at("root"), 0, set);
  std::map<int, LevelStats> levels;
  for (std::size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    LevelStats& stats = levels[tile.depth];
    for (std::size_t c : tile.children) stats.notMonotonic += set.tiles[c].declared > tile.declared;
    if (tile.uri.empty() || tile.children.empty()) continue;
    Mesh content, finest;
    appendContent(set, tile.uri, content);
    appendLeaves(set, t, finest);
    const SurfaceDistance d = surfaceDistance(content.positions, content.indices, finest.positions,
                                              finest.indices, samples, t + 1);
    stats.ratios.push_back(d.hausdorff / tile.declared);
    if (d.hausdorff > tile.declared) {
      ++stats.under;
      fmt::print(
          "under-declared: {} declares {:.4g}, measured {:.4g} (content to leaves {:.4g}, "
          "leaves to content {:.4g})\n",
          tile.uri, tile.declared, d.hausdorff, d.maxAB, d.maxBA);
    }
  }
  fmt::print("\n{}: {} tiles\n", directory.string(), set.tiles.size());
  fmt::print(
      "| depth | tiles measured | measured/declared min / median / max | under half | "
      "under-declared | child above parent |\n|---|---|---|---|---|---|\n");
  for (auto& [depth, stats] : levels) {
    std::vector<double>& r = stats.ratios;
    if (r.empty()) continue;
    std::sort(r.begin(), r.end());
    const auto half = std::count_if(r.begin(), r.end(), [](double x) { return x < 0.5; });
    fmt::print("| {} | {} | {:.2f} / {:.2f} / {:.2f} | {:.0f} % | {} | {} |\n", depth, r.size(),
               r.front(), r[r.size() / 2], r.back(),
               100.0 * static_cast<double>(half) / static_cast<double>(r.size()), stats.under,
               stats.notMonotonic);
  }
  std::fflush(stdout);
}

}  // namespace
}  // namespace lodforge

int main(int argc, char** argv) {
  std::uint32_t samples = 100'000;
  std::vector<std::string> directories;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--samples" && i + 1 < argc)
      samples = static_cast<std::uint32_t>(std::stoul(argv[++i]));
    else
      directories.push_back(arg);
  }
  if (directories.empty()) {
    std::fprintf(stderr, "usage: bench_tile_error [--samples N] TILESET_DIR...\n");
    return 2;
  }
  for (const std::string& d : directories) lodforge::measure(d, samples);
}
