#include "lodforge/tiles/implicit_tiling.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/tiles/tileset_json.h"

namespace lodforge {

namespace {

namespace fs = std::filesystem;

// A place in the implicit tree: a level below the root and coordinates there (also a subtree's,
// by its root's place).
struct ImplicitCoords {
  int level = 0;
  std::array<std::uint32_t, 3> xyz{};
  auto operator<=>(const ImplicitCoords&) const = default;
};

// The root's cell need not be (0, 0, 0) (the grid's corner comes from every input vertex, also
// ones no triangle uses): coordinates count from the root's cube.
ImplicitCoords coordsOf(const OctreeResult& octree, const OctreeNode& node) {
  const OctreeNode& root = octree.nodes[octree.root];
  assert(node.level <= root.level);
  ImplicitCoords c{root.level - node.level, {}};
  for (std::size_t a = 0; a < 3; ++a)
    c.xyz[a] = static_cast<std::uint32_t>(node.cell[a] - (root.cell[a] << c.level));
  return c;
}

// The subtree holding a tile, by its root's place (at a multiple of the subtree levels), and
// with `local` the tile's level and coordinates within it.
ImplicitCoords subtreeOf(const ImplicitCoords& c, int subtreeLevels,
                         ImplicitCoords* local = nullptr) {
  const int root = c.level / subtreeLevels * subtreeLevels;
  const int within = c.level - root;
  ImplicitCoords key{root, {}};
  for (std::size_t a = 0; a < 3; ++a) key.xyz[a] = c.xyz[a] >> within;
  if (local != nullptr) {
    local->level = within;
    for (std::size_t a = 0; a < 3; ++a) local->xyz[a] = c.xyz[a] & ((1u << within) - 1);
  }
  return key;
}

std::string subtreeUri(const ImplicitCoords& key) {
  return fmt::format("subtrees/{}/{}/{}/{}.subtree", key.level, key.xyz[0], key.xyz[1], key.xyz[2]);
}

// A tile of a subtree: its bit in the subtree's tile availability, and its node.
struct SubtreeTile {
  std::uint64_t bit = 0;
  std::uint32_t node = 0;
};

// A subtree's binary chunk: buffer views of whole 8-byte units, appended in order.
struct SubtreeBinary {
  std::vector<std::byte> bytes;
  nlohmann::json views = nlohmann::json::array();

  std::size_t add(std::span<const std::byte> data) {
    views.push_back({{"buffer", 0}, {"byteOffset", bytes.size()}, {"byteLength", data.size()}});
    bytes.insert(bytes.end(), data.begin(), data.end());
    bytes.resize((bytes.size() + 7) / 8 * 8, std::byte{0});
    return views.size() - 1;
  }
};

// An availability: a constant when every bit is the same, else a bitstream (bit i of byte i / 8,
// lowest first).
nlohmann::json availability(SubtreeBinary& binary, std::uint64_t bitCount,
                            std::span<const std::uint64_t> setBits) {
  if (setBits.empty()) return {{"constant", 0}};
  if (setBits.size() == bitCount) return {{"constant", 1}};
  std::vector<std::byte> bits((bitCount + 7) / 8, std::byte{0});
  for (std::uint64_t b : setBits)
    bits[b / 8] |= std::byte{static_cast<std::uint8_t>(1u << (b % 8))};
  return {{"bitstream", binary.add(bits)}, {"availableCount", setBits.size()}};
}

// The tile property table: each available tile's error and tight box, in bit order.
nlohmann::json tileTable(SubtreeBinary& binary, const OctreeResult& octree,
                         std::span<const double> errors, std::span<const SubtreeTile> tiles) {
  std::vector<double> error, box;
  for (const SubtreeTile& t : tiles) {
    error.push_back(errors[t.node]);
    const std::array<double, 12> b = tileBox(octree.nodes[t.node].bounds);
    box.insert(box.end(), b.begin(), b.end());
  }
  return {{"class", "tile"},
          {"count", tiles.size()},
          {"properties",
           {{"geometricError", {{"values", binary.add(std::as_bytes(std::span(error)))}}},
            {"boundingBox", {{"values", binary.add(std::as_bytes(std::span(box)))}}}}}};
}

// The schema of that table: the semantics that make viewers take the values as the tile's own.
nlohmann::json tileSchema() {
  const nlohmann::json scalar = {{"type", "SCALAR"}, {"componentType", "FLOAT64"}};
  nlohmann::json error = scalar, box = scalar;
  error["semantic"] = "TILE_GEOMETRIC_ERROR";
  box["array"] = true;
  box["count"] = 12;
  box["semantic"] = "TILE_BOUNDING_BOX";
  return {
      {"id", "lodforge"},
      {"classes", {{"tile", {{"properties", {{"geometricError", error}, {"boundingBox", box}}}}}}}};
}

// One subtree file's bytes ("subt" header, JSON, binary of 8-byte aligned bitstreams and the
// tile property table): its tiles and the set bits of its child subtrees. `errors` per node.
std::vector<std::byte> subtreeFile(const OctreeResult& octree, std::span<const double> errors,
                                   int subtreeLevels, std::vector<SubtreeTile> tiles,
                                   std::span<const std::uint64_t> childSubtrees) {
  std::sort(tiles.begin(), tiles.end(),
            [](const SubtreeTile& a, const SubtreeTile& b) { return a.bit < b.bit; });
  std::vector<std::uint64_t> tileBits, contentBits;
  for (const SubtreeTile& t : tiles) {
    tileBits.push_back(t.bit);
    if (hasTileContent(octree.nodes[t.node])) contentBits.push_back(t.bit);
  }
  std::vector<std::uint64_t> children(childSubtrees.begin(), childSubtrees.end());
  std::sort(children.begin(), children.end());
  SubtreeBinary binary;
  nlohmann::json json = {
      {"tileAvailability", availability(binary, levelOffset(subtreeLevels), tileBits)},
      {"contentAvailability",
       nlohmann::json::array({availability(binary, levelOffset(subtreeLevels), contentBits)})},
      {"childSubtreeAvailability",
       availability(binary, std::uint64_t{1} << (3 * subtreeLevels), children)}};
  json["propertyTables"] = nlohmann::json::array({tileTable(binary, octree, errors, tiles)});
  json["tileMetadata"] = 0;
  json["buffers"] = nlohmann::json::array({{{"byteLength", binary.bytes.size()}}});
  json["bufferViews"] = binary.views;
  std::string text = json.dump();
  text.resize((text.size() + 7) / 8 * 8, ' ');
  // Header: magic "subt", version 1, JSON and binary byte lengths (u64 each, little-endian).
  std::vector<std::byte> out(24 + text.size() + binary.bytes.size());
  const std::uint32_t version = 1;
  const std::uint64_t lengths[2] = {text.size(), binary.bytes.size()};
  std::memcpy(out.data(), "subt", 4);
  std::memcpy(out.data() + 4, &version, 4);
  std::memcpy(out.data() + 8, lengths, 16);
  std::memcpy(out.data() + 24, text.data(), text.size());
  std::copy(binary.bytes.begin(), binary.bytes.end(),
            out.begin() + 24 + static_cast<std::ptrdiff_t>(text.size()));
  return out;
}

// Every subtree's tiles and child subtree bits.
struct SubtreePlan {
  std::map<ImplicitCoords, std::vector<SubtreeTile>> tiles;
  std::map<ImplicitCoords, std::vector<std::uint64_t>> children;
};

SubtreePlan planSubtrees(const OctreeResult& octree, int subtreeLevels) {
  SubtreePlan plan;
  for (std::uint32_t i = 0; i < octree.nodes.size(); ++i) {
    const ImplicitCoords c = coordsOf(octree, octree.nodes[i]);
    ImplicitCoords local;
    const ImplicitCoords key = subtreeOf(c, subtreeLevels, &local);
    plan.tiles[key].push_back(
        {levelOffset(local.level) + mortonIndex(local.xyz[0], local.xyz[1], local.xyz[2]), i});
    if (local.level != 0 || c.level == 0) continue;
    // A subtree's root: a bit in the subtree above, at its bottom row's next level.
    const ImplicitCoords parent =
        subtreeOf({c.level - 1, {c.xyz[0] >> 1, c.xyz[1] >> 1, c.xyz[2] >> 1}}, subtreeLevels);
    std::uint32_t xyz[3];
    for (std::size_t a = 0; a < 3; ++a) xyz[a] = c.xyz[a] & ((1u << subtreeLevels) - 1);
    plan.children[parent].push_back(mortonIndex(xyz[0], xyz[1], xyz[2]));
  }
  return plan;
}

}  // namespace

std::uint64_t mortonIndex(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  std::uint64_t m = 0;
  for (int b = 0; b < 21; ++b) {
    m |= std::uint64_t{(x >> b) & 1u} << (3 * b);
    m |= std::uint64_t{(y >> b) & 1u} << (3 * b + 1);
    m |= std::uint64_t{(z >> b) & 1u} << (3 * b + 2);
  }
  return m;
}

std::uint64_t levelOffset(int level) {
  return ((std::uint64_t{1} << (3 * level)) - 1) / 7;
}

bool implicitTilingFits(const OctreeResult& octree) {
  const OctreeNode& root = octree.nodes[octree.root];
  if (root.level != octree.levels) return false;  // a root added over a --levels cut
  for (const OctreeNode& node : octree.nodes)
    for (std::uint32_t c : node.children) {
      const OctreeNode& child = octree.nodes[c];
      if (child.level != node.level - 1) return false;
      for (std::size_t a = 0; a < 3; ++a)
        if ((child.cell[a] >> 1) != node.cell[a]) return false;
    }
  return true;
}

Status placeContents(const OctreeResult& octree, const std::string& directory, bool implicit) {
  const fs::path dir(directory);
  std::error_code error;
  for (const OctreeNode& node : octree.nodes) {
    if (!hasTileContent(node)) continue;
    const std::string explicitUri = tileContentUri(node),
                      implicitUri = implicitContentUri(octree, node);
    const fs::path to = dir / (implicit ? implicitUri : explicitUri);
    const fs::path from = dir / (implicit ? explicitUri : implicitUri);
    if (fs::exists(to, error)) continue;  // where an interrupted attempt already put it
    fs::create_directories(to.parent_path(), error);
    if (!error) fs::rename(from, to, error);
    if (error)
      return ioError(to.string(), fmt::format("cannot move a tile there: {}", error.message()));
  }
  if (implicit) return {};
  // What an interrupted implicit attempt left: its subtree files and emptied folders.
  fs::remove_all(dir / "subtrees", error);
  for (const auto& entry : fs::directory_iterator(dir / "tiles", error))
    if (entry.is_directory()) fs::remove_all(entry.path(), error);
  return {};
}

std::string implicitContentUri(const OctreeResult& octree, const OctreeNode& node) {
  const ImplicitCoords c = coordsOf(octree, node);
  return fmt::format("tiles/{}/{}/{}/{}.glb", c.level, c.xyz[0], c.xyz[1], c.xyz[2]);
}

Status writeImplicitTileset(const OctreeResult& octree, const ChunkGrid& grid,
                            const std::string& directory, const std::optional<Mat4d>& rootTransform,
                            bool quantized, const std::string& partsUri, int subtreeLevels) {
  assert(implicitTilingFits(octree) && subtreeLevels >= 1);
  const int levels = octree.nodes[octree.root].level + 1;
  subtreeLevels = std::min(subtreeLevels, levels);
  const std::vector<double> errors = declaredTileErrors(octree, quantized);
  const SubtreePlan plan = planSubtrees(octree, subtreeLevels);
  for (const auto& [key, tiles] : plan.tiles) {
    const auto found = plan.children.find(key);
    std::span<const std::uint64_t> children;
    if (found != plan.children.end()) children = found->second;
    const std::vector<std::byte> bytes =
        subtreeFile(octree, errors, subtreeLevels, tiles, children);
    const fs::path path = fs::path(directory) / subtreeUri(key);
    std::error_code error;
    fs::create_directories(path.parent_path(), error);
    if (error) return ioError(path.string(), fmt::format("cannot create: {}", error.message()));
    LODFORGE_TRY(OutputFile::writeWhole(
        path.string(),
        std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size())));
  }
  // For viewers that ignore the metadata: the root's error halves per level and stays at or
  // above every tile's own.
  double rootError = 0;
  for (std::size_t i = 0; i < octree.nodes.size(); ++i)
    rootError = std::max(rootError, std::ldexp(errors[i], coordsOf(octree, octree.nodes[i]).level));
  const double cube = grid.size * std::ldexp(1.0, levels - 1);
  const ChunkCell& cell = octree.nodes[octree.root].cell;
  const Vec3d corner = grid.origin + Vec3d{cell[0] * cube, cell[1] * cube, cell[2] * cube};
  nlohmann::json root = {
      {"boundingVolume", {{"box", tileBox(Aabbd{corner, corner + Vec3d{cube, cube, cube}})}}},
      {"geometricError", rootError},
      {"refine", "REPLACE"},
      {"content", {{"uri", "tiles/{level}/{x}/{y}/{z}.glb"}}},
      {"implicitTiling",
       {{"subdivisionScheme", "OCTREE"},
        {"subtreeLevels", subtreeLevels},
        {"availableLevels", levels},
        {"subtrees", {{"uri", "subtrees/{level}/{x}/{y}/{z}.subtree"}}}}}};
  if (rootTransform) root["transform"] = rootTransform->m;
  nlohmann::json tileset = {
      {"asset", {{"version", "1.1"}, {"generator", "lodforge " LODFORGE_VERSION}}},
      {"schema", tileSchema()},
      {"geometricError", std::max(rootError, nothingShownError(octree, errors[octree.root]))},
      {"root", root}};
  if (!partsUri.empty()) tileset["asset"]["extras"]["parts"] = partsUri;
  return OutputFile::writeWhole(directory + "/tileset.json", tileset.dump(1) + '\n');
}

}  // namespace lodforge
