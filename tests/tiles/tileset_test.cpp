#include "lodforge/tiles/tileset.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace lodforge {
namespace {

namespace fs = std::filesystem;

struct Box {
  double c[3], h[3];
};

Box boxOf(const nlohmann::json& tile) {
  const auto& b = tile.at("boundingVolume").at("box");
  Box box{};
  for (int i = 0; i < 3; ++i) {
    box.c[i] = b.at(static_cast<std::size_t>(i)).get<double>();
    box.h[i] = b.at(static_cast<std::size_t>(3 + 4 * i)).get<double>();  // axis-aligned
  }
  return box;
}

// The rules of docs/tiles.md: errors non-increasing, children inside parents, contents exist.
void checkTile(const nlohmann::json& tile, const fs::path& directory, double parentError,
               const Box* parent, int& contents) {
  const double error = tile.at("geometricError").get<double>();
  EXPECT_LE(error, parentError);
  EXPECT_EQ(tile.at("refine"), "REPLACE");
  const Box box = boxOf(tile);
  if (parent != nullptr) {
    for (int i = 0; i < 3; ++i) {
      const double slack = 1e-9 * (1 + std::abs(parent->c[i]));
      EXPECT_GE(box.c[i] - box.h[i], parent->c[i] - parent->h[i] - slack);
      EXPECT_LE(box.c[i] + box.h[i], parent->c[i] + parent->h[i] + slack);
    }
  }
  if (tile.contains("content")) {
    const fs::path file = directory / tile["content"]["uri"].get<std::string>();
    ASSERT_TRUE(fs::exists(file)) << file;
    std::ifstream in(file, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    EXPECT_EQ(std::memcmp(magic, "glTF", 4), 0);
    ++contents;
  }
  for (const auto& child : tile.value("children", nlohmann::json::array()))
    checkTile(child, directory, error, &box, contents);
}

TEST(Tiles, HorseTilesetFollowsTheRules) {
  const fs::path out = fs::path(::testing::TempDir()) / "horse-tiles";
  fs::remove_all(out);
  TilesOptions options;
  options.input.chunkSize = 0.05;  // the horse is ~0.2 m long: a few chunks per axis
  options.octree.errorSamples = 2000;
  Result<TilesStats> stats =
      writeTiles(std::string(LODFORGE_DATA_DIR) + "/meshes/horse.ply", out.string(), options);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_GE(stats->levels, 2);
  EXPECT_GT(stats->leaves, 8u);
  std::ifstream in(out / "tileset.json");
  const nlohmann::json tileset = nlohmann::json::parse(in);
  EXPECT_EQ(tileset.at("asset").at("version"), "1.1");
  int contents = 0;
  checkTile(tileset.at("root"), out, tileset.at("geometricError").get<double>(), nullptr, contents);
  EXPECT_EQ(static_cast<std::uint64_t>(contents), stats->tiles);
  EXPECT_EQ(static_cast<std::uint64_t>(
                std::distance(fs::directory_iterator(out / "tiles"), fs::directory_iterator{})),
            stats->tiles);
  // Nothing but the tileset is left behind: no staging or work directories.
  for (const auto& entry : fs::directory_iterator(out.parent_path()))
    EXPECT_EQ(entry.path().filename().string().find("horse-tiles."), std::string::npos)
        << entry.path();
}

TEST(Tiles, BadInputIsRefusedWithoutLeavingAnything) {
  const fs::path dir = fs::path(::testing::TempDir()) / "bad-tiles";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path input = dir / "broken.ply";
  std::ofstream(input)
      << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n";
  Result<TilesStats> stats = writeTiles(input.string(), (dir / "out").string(), {});
  ASSERT_FALSE(stats.ok());
  EXPECT_EQ(stats.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(stats.error().message.find("broken.ply"), std::string::npos);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1);
}

TEST(Tiles, RefusesToOverwriteADirectoryThatIsNotATileset) {
  const fs::path dir = fs::path(::testing::TempDir()) / "not-a-tileset";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "precious.txt") << "keep me";
  Result<TilesStats> stats =
      writeTiles(std::string(LODFORGE_DATA_DIR) + "/meshes/horse.ply", dir.string(), {});
  ASSERT_FALSE(stats.ok());
  EXPECT_EQ(stats.error().kind, ErrorKind::kUsage);
  EXPECT_TRUE(fs::exists(dir / "precious.txt"));
}

}  // namespace
}  // namespace lodforge
