#include "lodforge/generate/scan_texture.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "lodforge/core/mesh.h"
#include "lodforge/generate/scan.h"
#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

TEST(ScanTexture, RegionsCutTheGridIntoWholeCellsAndCoverItOnce) {
  for (const auto& [atlases, columns, rows] : {std::tuple{16u, 100u, 67u}, std::tuple{6u, 7u, 5u},
                                               std::tuple{1u, 3u, 3u}, std::tuple{12u, 2u, 40u}}) {
    const ScanAtlasLayout layout = ScanAtlasLayout::of(atlases, columns, rows);
    EXPECT_LE(layout.count(), atlases);
    std::vector<int> covered(std::size_t{columns} * rows, 0);
    for (std::uint32_t r = 0; r < layout.count(); ++r) {
      const auto cells = layout.cells(r);
      ASSERT_LT(cells[0], cells[1]);
      ASSERT_LT(cells[2], cells[3]);
      for (std::uint64_t y = cells[2]; y < cells[3]; ++y)
        for (std::uint64_t x = cells[0]; x < cells[1]; ++x) {
          ++covered[y * columns + x];
          EXPECT_EQ(layout.regionOf(x, y), r) << x << "," << y;
        }
    }
    for (int c : covered) ASSERT_EQ(c, 1);
  }
}

TEST(ScanTexture, ATexturedScanNamesItsAtlasesAndEveryCornerLiesInOne) {
  test::TempDir dir;
  const std::string path = dir.file("scan.ply");
  Result<GenerateStats> stats =
      generateScan({.triangles = 20'000, .seed = 3, .textureSize = 64, .atlases = 6}, path);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  for (std::uint32_t r = 0; r < 6; ++r) {
    ImageSource atlas{.name = "atlas", .path = dir.file(scanAtlasName(path, r))};
    ASSERT_TRUE(probeImage(atlas).ok()) << atlas.path;
    EXPECT_EQ(atlas.width, 64u);
    EXPECT_EQ(atlas.format, ImageFormat::kJpeg);
  }
  std::vector<std::string> warnings;
  Result<Model> model = readPly(path, {.warnings = &warnings});
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(model->triangleCount(), 20'000u);
  EXPECT_EQ(model->images.size(), 6u);
  EXPECT_EQ(model->objectCount(), 6u);  // an object per atlas
  EXPECT_FALSE(model->hasColors());     // the texture instead
  for (const Vec2f& uv : model->uvs) {
    ASSERT_GE(uv.x, 0.0f);
    ASSERT_LE(uv.x, 1.0f);
    ASSERT_GE(uv.y, 0.0f);
    ASSERT_LE(uv.y, 1.0f);
  }
  // Atlases differ (the ground goes on), and a second run may replace its own atlases.
  Result<Image> a = decodeImage(model->images[0]), b = decodeImage(model->images[1]);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NE(a->rgba, b->rgba);
  EXPECT_TRUE(
      generateScan({.triangles = 200, .seed = 3, .textureSize = 64, .atlases = 6}, path).ok());
}

TEST(ScanTexture, AFileInTheAtlasesPlaceThatIsNotOneIsNeverReplaced) {
  test::TempDir dir;
  const std::string path = dir.file("scan.ply");
  test::writeFile(dir.file(scanAtlasName(path, 1)), "my holiday photo");
  Result<GenerateStats> stats =
      generateScan({.triangles = 2'000, .seed = 3, .textureSize = 32, .atlases = 4}, path);
  ASSERT_FALSE(stats.ok());
  EXPECT_EQ(stats.error().kind, ErrorKind::kUsage);
  EXPECT_EQ(test::readFile(dir.file(scanAtlasName(path, 1))), "my holiday photo");
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace lodforge
