#include "lodforge/tiles/implicit_tiling.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lodforge/tiles/tileset.h"
#include "lodforge/tiles/tileset_json.h"
#include "lodforge/tiles/tileset_output.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

std::string readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The order the 3D Tiles specification gives for octree availability (a plain reading of its
// Morton order, bits interleaved x, y, z), and where each level's bits start.
TEST(ImplicitTiling, MortonOrderAndLevelOffsetsFollowTheSpecification) {
  EXPECT_EQ(mortonIndex(0, 0, 0), 0u);
  EXPECT_EQ(mortonIndex(1, 0, 0), 1u);
  EXPECT_EQ(mortonIndex(0, 1, 0), 2u);
  EXPECT_EQ(mortonIndex(0, 0, 1), 4u);
  EXPECT_EQ(mortonIndex(1, 1, 1), 7u);
  EXPECT_EQ(mortonIndex(2, 0, 0), 8u);
  EXPECT_EQ(mortonIndex(3, 5, 6), 0b110'101'011u | 0u);  // x=011, y=101, z=110 by bit
  EXPECT_EQ(levelOffset(0), 0u);
  EXPECT_EQ(levelOffset(1), 1u);
  EXPECT_EQ(levelOffset(2), 9u);
  EXPECT_EQ(levelOffset(3), 73u);
}

// Contents move to their implicit names counted from the root's cube (here not at cell 0), again
// without harm (a resumed run), and back to their explicit names with nothing of the implicit
// layout left (a resumed run that writes the explicit one).
TEST(ImplicitTiling, ContentsMoveBetweenTheLayoutsAsOftenAsARunIsResumed) {
  const test::TempDir temp;
  OctreeResult octree;
  octree.levels = 1;
  octree.nodes.resize(3);
  for (int i = 0; i < 2; ++i) octree.nodes[static_cast<std::size_t>(i)].cell = {4 + i, 2, 0};
  octree.nodes[2].level = 1;
  octree.nodes[2].cell = {2, 1, 0};
  octree.nodes[2].children = {0, 1};
  octree.root = 2;
  for (OctreeNode& node : octree.nodes) node.triangles = 1, node.meshPath = "mesh";
  ASSERT_TRUE(implicitTilingFits(octree));
  const fs::path dir = temp.path();
  fs::create_directories(dir / "tiles");
  for (const OctreeNode& node : octree.nodes)
    std::ofstream(dir / tileContentUri(node)) << node.cell[0];
  ASSERT_TRUE(placeContents(octree, dir.string(), true).ok());
  ASSERT_TRUE(placeContents(octree, dir.string(), true).ok());
  EXPECT_EQ(readBytes(dir / "tiles/0/0/0/0.glb"), "2");
  EXPECT_EQ(readBytes(dir / "tiles/1/0/0/0.glb"), "4");
  EXPECT_EQ(readBytes(dir / "tiles/1/1/0/0.glb"), "5");
  fs::create_directories(dir / "subtrees/0/0/0");
  std::ofstream(dir / "subtrees/0/0/0/0.subtree") << "left by an interrupted run";
  ASSERT_TRUE(placeContents(octree, dir.string(), false).ok());
  std::vector<std::string> left;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    left.push_back(fs::relative(entry.path(), dir).string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"tiles", "tiles/0-4-2-0.glb", "tiles/0-5-2-0.glb",
                                            "tiles/1-2-1-0.glb"}));
}

// What the explicit tileset.json says of each tile, by its content's explicit name
// (level-x-y-z, the level counted from the leaves).
struct ExplicitTile {
  double error = 0;
  std::vector<double> box;
  bool content = false;
};

void collectExplicit(const nlohmann::json& tile, std::map<std::string, ExplicitTile>& out,
                     std::vector<ExplicitTile>& unnamed) {
  ExplicitTile t{tile.at("geometricError").get<double>(),
                 tile.at("boundingVolume").at("box").get<std::vector<double>>(),
                 tile.contains("content")};
  if (t.content) {
    std::string uri = tile["content"]["uri"].get<std::string>();  // tiles/L-X-Y-Z.glb
    out[uri.substr(6, uri.size() - 10)] = t;
  } else {
    unnamed.push_back(t);
  }
  for (const auto& child : tile.value("children", nlohmann::json::array()))
    collectExplicit(child, out, unnamed);
}

// A subtree file read by the specification (not through the writer's code): its JSON, and each
// availability as a bit test.
struct Subtree {
  nlohmann::json json;
  std::string binary;

  bool bit(const nlohmann::json& availability, std::uint64_t i) const {
    if (availability.contains("constant")) return availability["constant"].get<int>() == 1;
    const nlohmann::json& view = json["bufferViews"][availability["bitstream"].get<std::size_t>()];
    const std::size_t at = view["byteOffset"].get<std::size_t>() + i / 8;
    EXPECT_LT(i / 8, view["byteLength"].get<std::size_t>());
    return ((static_cast<unsigned char>(binary[at]) >> (i % 8)) & 1u) != 0;
  }
  std::vector<double> values(const std::string& property) const {
    const nlohmann::json& table = json["propertyTables"][json["tileMetadata"].get<std::size_t>()];
    const nlohmann::json& view =
        json["bufferViews"][table["properties"][property]["values"].get<std::size_t>()];
    std::vector<double> out(view["byteLength"].get<std::size_t>() / 8);
    std::memcpy(out.data(), binary.data() + view["byteOffset"].get<std::size_t>(), out.size() * 8);
    return out;
  }
};

Subtree readSubtree(const fs::path& path) {
  const std::string bytes = readBytes(path);
  EXPECT_GE(bytes.size(), 24u) << path;
  EXPECT_EQ(bytes.substr(0, 4), "subt");
  std::uint32_t version = 0;
  std::uint64_t lengths[2] = {};
  std::memcpy(&version, bytes.data() + 4, 4);
  std::memcpy(lengths, bytes.data() + 8, 16);
  EXPECT_EQ(version, 1u);
  EXPECT_EQ(lengths[0] % 8, 0u);
  EXPECT_EQ(24 + lengths[0] + lengths[1], bytes.size());
  Subtree s;
  s.json = nlohmann::json::parse(bytes.substr(24, lengths[0]));
  s.binary = bytes.substr(24 + lengths[0]);
  if (s.json.contains("buffers")) {
    EXPECT_EQ(s.json["buffers"][0]["byteLength"], lengths[1]);
  }
  return s;
}

std::uint64_t morton(std::uint32_t x, std::uint32_t y, std::uint32_t z, int bits) {
  std::uint64_t m = 0;
  for (int b = 0; b < bits; ++b)
    m |= (std::uint64_t{(x >> b) & 1u} << (3 * b)) | (std::uint64_t{(y >> b) & 1u} << (3 * b + 1)) |
         (std::uint64_t{(z >> b) & 1u} << (3 * b + 2));
  return m;
}

// Every tile of an implicit tileset, expanded from its root through the subtree files: its
// level (from the root), coordinates, error, box and whether it has content.
struct ImplicitTile {
  int level = 0;
  std::uint32_t x = 0, y = 0, z = 0;
  double error = 0;
  std::vector<double> box;
  bool content = false;
};

std::vector<ImplicitTile> expandImplicit(const fs::path& dir, const nlohmann::json& implicit) {
  const int levels = implicit["availableLevels"].get<int>();
  const int per = implicit["subtreeLevels"].get<int>();
  std::vector<ImplicitTile> out;
  std::function<void(int, std::uint32_t, std::uint32_t, std::uint32_t)> subtree =
      [&](int rootLevel, std::uint32_t rx, std::uint32_t ry, std::uint32_t rz) {
        const Subtree s =
            readSubtree(dir / fmt::format("subtrees/{}/{}/{}/{}.subtree", rootLevel, rx, ry, rz));
        const std::vector<double> errors = s.values("geometricError");
        const std::vector<double> boxes = s.values("boundingBox");
        std::size_t row = 0;  // tiles are in bit order in the property table
        for (int l = 0; l < per && rootLevel + l < levels; ++l) {
          const std::uint64_t first = ((std::uint64_t{1} << (3 * l)) - 1) / 7;
          const std::uint32_t side = 1u << l;
          std::vector<std::array<std::uint32_t, 4>> level;  // (morton, x, y, z)
          for (std::uint32_t z = 0; z < side; ++z)
            for (std::uint32_t y = 0; y < side; ++y)
              for (std::uint32_t x = 0; x < side; ++x) level.push_back({0, x, y, z});
          for (auto& c : level) c[0] = static_cast<std::uint32_t>(morton(c[1], c[2], c[3], l));
          std::sort(level.begin(), level.end());
          for (const auto& c : level) {
            const std::uint64_t b = first + c[0];
            if (!s.bit(s.json["tileAvailability"], b)) {
              EXPECT_FALSE(s.bit(s.json["contentAvailability"][0], b));
              continue;
            }
            ImplicitTile t;
            t.level = rootLevel + l;
            t.x = (rx << l) | c[1];
            t.y = (ry << l) | c[2];
            t.z = (rz << l) | c[3];
            t.error = errors.at(row);
            t.box.assign(boxes.begin() + static_cast<std::ptrdiff_t>(12 * row),
                         boxes.begin() + static_cast<std::ptrdiff_t>(12 * row + 12));
            t.content = s.bit(s.json["contentAvailability"][0], b);
            out.push_back(t);
            ++row;
          }
        }
        EXPECT_EQ(row, errors.size());
        const std::uint32_t side = 1u << per;
        for (std::uint32_t z = 0; z < side; ++z)
          for (std::uint32_t y = 0; y < side; ++y)
            for (std::uint32_t x = 0; x < side; ++x)
              if (s.bit(s.json["childSubtreeAvailability"], morton(x, y, z, per)))
                subtree(rootLevel + per, (rx << per) | x, (ry << per) | y, (rz << per) | z);
      };
  subtree(0, 0, 0, 0);
  return out;
}

// The same octree written both ways: the implicit tileset, read back by the specification's
// rules alone, has exactly the explicit one's tiles, errors, boxes and content bytes.
TEST(ImplicitTiling, AnImplicitTilesetHoldsExactlyTheExplicitOnesTiles) {
  const test::TempDir temp;
  TilesOptions options;
  options.input.chunkSize = 0.012;  // the horse is ~0.2 m long: five levels above the leaves
  options.octree.errorSamples = 500;
  options.implicitTiling = ImplicitTiling::kOff;
  const std::string horse = test::dataPath("meshes/horse.ply");
  Result<TilesStats> explicitStats = writeTiles(horse, temp.file("explicit"), options);
  ASSERT_TRUE(explicitStats.ok()) << explicitStats.error().message;
  options.implicitTiling = ImplicitTiling::kOn;
  options.subtreeLevels = 2;  // several rows of subtree files
  Result<TilesStats> implicitStats = writeTiles(horse, temp.file("implicit"), options);
  ASSERT_TRUE(implicitStats.ok()) << implicitStats.error().message;
  EXPECT_FALSE(explicitStats->implicitTiling);
  EXPECT_TRUE(implicitStats->implicitTiling);
  ASSERT_GE(implicitStats->levels, 4);

  std::map<std::string, ExplicitTile> named;
  std::vector<ExplicitTile> unnamed;
  const nlohmann::json explicitJson =
      nlohmann::json::parse(readBytes(fs::path(temp.file("explicit")) / "tileset.json"));
  collectExplicit(explicitJson["root"], named, unnamed);
  const fs::path dir = temp.file("implicit");
  const nlohmann::json implicitJson = nlohmann::json::parse(readBytes(dir / "tileset.json"));
  const nlohmann::json& root = implicitJson["root"];
  EXPECT_FALSE(root.contains("children"));
  EXPECT_EQ(root["implicitTiling"]["subdivisionScheme"], "OCTREE");
  const int levels = root["implicitTiling"]["availableLevels"].get<int>();
  EXPECT_EQ(levels, implicitStats->levels + 1);
  EXPECT_EQ(implicitJson["schema"]["classes"]["tile"]["properties"]["geometricError"]["semantic"],
            "TILE_GEOMETRIC_ERROR");

  const std::vector<ImplicitTile> tiles = expandImplicit(dir, root["implicitTiling"]);
  std::size_t subtreeFiles = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir / "subtrees"))
    subtreeFiles += entry.is_regular_file() ? 1 : 0;
  EXPECT_GE(subtreeFiles, 3u);  // rows at levels 0, 2 and 4
  EXPECT_EQ(tiles.size(), named.size() + unnamed.size());
  std::size_t matched = 0;
  const double rootError = root["geometricError"].get<double>();
  for (const ImplicitTile& t : tiles) {
    // Viewers that ignore the metadata halve the root's error per level: never below the tile's.
    EXPECT_GE(std::ldexp(rootError, -t.level), t.error);
    if (!t.content) continue;
    const std::string name = fmt::format("{}-{}-{}-{}", levels - 1 - t.level, t.x, t.y, t.z);
    const auto it = named.find(name);
    ASSERT_NE(it, named.end()) << name;
    EXPECT_EQ(t.error, it->second.error) << name;
    EXPECT_EQ(t.box, it->second.box) << name;
    const fs::path glb = dir / fmt::format("tiles/{}/{}/{}/{}.glb", t.level, t.x, t.y, t.z);
    EXPECT_EQ(readBytes(glb),
              readBytes(fs::path(temp.file("explicit")) / ("tiles/" + name + ".glb")))
        << name;
    ++matched;
  }
  EXPECT_EQ(matched, named.size());
  // Tiles without content have no name: the same errors and boxes, in any order.
  std::vector<std::pair<double, std::vector<double>>> explicitEmpty, implicitEmpty;
  for (const ExplicitTile& t : unnamed) explicitEmpty.emplace_back(t.error, t.box);
  for (const ImplicitTile& t : tiles)
    if (!t.content) implicitEmpty.emplace_back(t.error, t.box);
  std::sort(explicitEmpty.begin(), explicitEmpty.end());
  std::sort(implicitEmpty.begin(), implicitEmpty.end());
  EXPECT_EQ(explicitEmpty, implicitEmpty);
  // The root: the explicit root's error and box in the metadata.
  ASSERT_FALSE(tiles.empty());
  EXPECT_EQ(tiles.front().level, 0);
  EXPECT_EQ(tiles.front().error, explicitJson["root"]["geometricError"].get<double>());
  EXPECT_EQ(tiles.front().box,
            explicitJson["root"]["boundingVolume"]["box"].get<std::vector<double>>());
  // Ours to replace on the next run, and no longer once it holds a file we did not write.
  EXPECT_TRUE(isLodforgeTileset(dir.string()));
  std::ofstream(dir / "tiles" / "0" / "notes.txt") << "someone's";
  EXPECT_FALSE(isLodforgeTileset(dir.string()));
}

}  // namespace
}  // namespace lodforge
