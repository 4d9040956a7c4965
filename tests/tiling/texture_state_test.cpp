#include "lodforge/tiling/texture_state.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_support.h"

namespace lodforge {
namespace {

// A table of a file image and an embedded one, and two materials using them with their modes.
TextureTable sampleTable(const test::TempDir& dir) {
  test::writeFile(dir.file("atlas.jpg"), "not really a jpeg, but bytes");
  TextureTable table;
  ImageSource file{.name = "atlas.jpg", .path = dir.file("atlas.jpg")};
  file.format = ImageFormat::kJpeg, file.width = 64, file.height = 32, file.channels = 3;
  ImageSource embedded{.name = "image 1"};
  embedded.bytes = {std::byte{1}, std::byte{2}, std::byte{3}};
  embedded.format = ImageFormat::kPng, embedded.width = 8, embedded.height = 8;
  embedded.channels = 4;
  table.images = {file, embedded};
  Material a{.name = "a", .baseColorImage = 0};
  a.wrapS = TextureWrap::kMirror, a.wrapT = TextureWrap::kClamp;
  Material b{.name = "b", .baseColor = {0.5f, 0.25f, 1, 1}, .baseColorImage = 1};
  table.materials = {a, b, Material{.name = "plain"}};
  return table;
}

void expectSameTable(const TextureTable& a, const TextureTable& b) {
  EXPECT_EQ(a.materials, b.materials);
  ASSERT_EQ(a.images.size(), b.images.size());
  for (std::size_t i = 0; i < a.images.size(); ++i) {
    EXPECT_EQ(a.images[i].name, b.images[i].name);
    EXPECT_EQ(a.images[i].path, b.images[i].path);
    EXPECT_EQ(a.images[i].bytes, b.images[i].bytes);
    EXPECT_EQ(a.images[i].format, b.images[i].format);
    EXPECT_EQ(a.images[i].width, b.images[i].width);
    EXPECT_EQ(a.images[i].height, b.images[i].height);
    EXPECT_EQ(a.images[i].channels, b.images[i].channels);
  }
}

TEST(TextureState, TheTableComesBackWhileItsImagesAreUnchanged) {
  test::TempDir dir;
  const TextureTable table = sampleTable(dir);
  Result<nlohmann::json> saved = saveTextureTable(table, dir.file("work"));
  ASSERT_TRUE(saved.ok()) << saved.status().message();
  const std::optional<TextureTable> back = loadTextureTable(*saved, dir.file("work"));
  ASSERT_TRUE(back.has_value());
  expectSameTable(table, *back);
  // Through text, as the state file holds it.
  const auto reparsed = nlohmann::json::parse(saved->dump());
  ASSERT_TRUE(loadTextureTable(reparsed, dir.file("work")).has_value());
}

TEST(TextureState, AChangedOrDamagedImageOrABadMaterialMeansStartingOver) {
  test::TempDir dir;
  const TextureTable table = sampleTable(dir);
  Result<nlohmann::json> saved = saveTextureTable(table, dir.file("work"));
  ASSERT_TRUE(saved.ok());
  // The image file edited (one byte more).
  test::writeFile(dir.file("atlas.jpg"), "not really a jpeg, but bytes!");
  EXPECT_FALSE(loadTextureTable(*saved, dir.file("work")).has_value());
  test::writeFile(dir.file("atlas.jpg"), "not really a jpeg, but bytes");
  // (Rewritten: same size, but a later modification time.)
  std::filesystem::last_write_time(
      dir.file("atlas.jpg"),
      std::filesystem::last_write_time(dir.file("atlas.jpg")) + std::chrono::seconds(5));
  EXPECT_FALSE(loadTextureTable(*saved, dir.file("work")).has_value());
  saved = saveTextureTable(table, dir.file("work"));
  ASSERT_TRUE(saved.ok());
  ASSERT_TRUE(loadTextureTable(*saved, dir.file("work")).has_value());
  // The embedded image's work file damaged, or gone.
  const std::string embedded = dir.file("work/images/1.image");
  ASSERT_TRUE(std::filesystem::exists(embedded));
  test::writeFile(embedded, std::string("\x01\x02\x04", 3));
  EXPECT_FALSE(loadTextureTable(*saved, dir.file("work")).has_value());
  std::filesystem::remove(embedded);
  EXPECT_FALSE(loadTextureTable(*saved, dir.file("work")).has_value());
  // A material naming an image the table lacks, or an unknown wrap mode.
  saved = saveTextureTable(table, dir.file("work"));
  ASSERT_TRUE(saved.ok());
  nlohmann::json bad = *saved;
  bad["materials"][0][8] = 7;
  EXPECT_FALSE(loadTextureTable(bad, dir.file("work")).has_value());
  bad = *saved;
  bad["materials"][1][9] = 9;
  EXPECT_FALSE(loadTextureTable(bad, dir.file("work")).has_value());
  // Malformed: thrown, for resumeChunks to catch.
  bad = *saved;
  bad["images"][0].erase("width");
  EXPECT_THROW(loadTextureTable(bad, dir.file("work")), nlohmann::json::exception);
}

}  // namespace
}  // namespace lodforge
