#include "lodforge/generate/points.h"

#include <gtest/gtest.h>

#include <cstring>
#include <map>

#include "lodforge/core/threads.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/points/las_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

TEST(Points, ExactCountWithUnitNormalsAndColours) {
  test::TempDir dir;
  Result<GenerateStats> stats = generatePoints({.points = 100'001, .seed = 3}, dir.file("p.ply"));
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  Result<Model> model = readPly(dir.file("p.ply"));
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->vertexCount(), 100'001u);
  EXPECT_EQ(model->triangleCount(), 0u);
  ASSERT_TRUE(model->hasNormals());
  ASSERT_TRUE(model->hasColors());
  for (const Vec3f& n : model->normals) ASSERT_NEAR(length(n), 1.0f, 1e-5f);
  // Spread over the whole 1000 x 667 m domain.
  const Aabb box = model->bounds();
  EXPECT_GT(box.size().x, 900.0f);
  EXPECT_GT(box.size().y, 600.0f);
}

TEST(Points, DeterministicWhateverTheThreadCount) {
  test::TempDir dir;
  {
    const ThreadLimit one(1);
    ASSERT_TRUE(generatePoints({.points = 70'000, .seed = 8}, dir.file("one.ply")).ok());
  }
  {
    const ThreadLimit two(2);
    ASSERT_TRUE(generatePoints({.points = 70'000, .seed = 8}, dir.file("two.ply")).ok());
  }
  EXPECT_EQ(test::readFile(dir.file("one.ply")), test::readFile(dir.file("two.ply")));
}

// LAS output: the same points as the PLY, with lidar fields that fit the terrain.
TEST(Points, LasHasTheSamePointsWithLidarAttributes) {
  test::TempDir dir;
  const PointsOptions options{.points = 40'000, .seed = 5};
  ASSERT_TRUE(generatePoints(options, dir.file("p.ply")).ok());
  Result<GenerateStats> stats = generatePoints(options, dir.file("p.las"));
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  Result<Model> ply = readPly(dir.file("p.ply"));
  ASSERT_TRUE(ply.ok());
  Result<LasReader> las = LasReader::open(dir.file("p.las"), 1 << 20);
  ASSERT_TRUE(las.ok()) << las.status().message();
  const LasHeader& h = las->header();
  EXPECT_EQ(h.pointFormat, 3);
  ASSERT_EQ(h.pointCount, 40'000u);
  std::vector<std::byte> records;
  ASSERT_TRUE(*las->nextRecords(records));
  ASSERT_EQ(records.size(), 40'000u * 34);
  std::map<int, int> classes;
  int multipleReturns = 0, vegetationWithReturns = 0, vegetation = 0;
  for (std::size_t i = 0; i < 40'000; ++i) {
    const std::byte* r = records.data() + 34 * i;
    std::int32_t xyz[3];
    std::memcpy(xyz, r, 12);
    const int cls = static_cast<int>(r[15]) & 31;
    ++classes[cls];
    for (int k = 0; k < 3; ++k) {  // the PLY holds floats; noise points are lifted in the LAS
      if (cls != 7) {
        ASSERT_NEAR(xyz[k] * 0.001, ply->positions[i][k], 2e-3) << i;
      }
    }
    const int returns = (static_cast<int>(r[14]) >> 3) & 7, number = static_cast<int>(r[14]) & 7;
    ASSERT_GE(returns, 1);
    ASSERT_TRUE(number >= 1 && number <= returns);
    multipleReturns += returns > 1;
    if (cls >= 3 && cls <= 5) {
      ++vegetation;
      vegetationWithReturns += returns > 1;
    }
    std::uint16_t intensity;
    std::memcpy(&intensity, r + 12, 2);
    EXPECT_GT(intensity, 0);
  }
  // Ground dominates, vegetation and water are there, noise is rare; only vegetation has
  // several returns.
  EXPECT_GT(classes[2], 20'000);
  EXPECT_GT(classes[3] + classes[4] + classes[5], 2'000);
  EXPECT_GT(classes[9], 0);
  EXPECT_LT(classes[7], 200);
  EXPECT_EQ(vegetationWithReturns, multipleReturns);
  EXPECT_EQ(vegetationWithReturns, vegetation);
  // Header counts by return and bounds agree with the records.
  EXPECT_GT(h.bounds.max.x - h.bounds.min.x, 900.0);
  // Deterministic.
  ASSERT_TRUE(generatePoints(options, dir.file("q.las")).ok());
  EXPECT_EQ(test::readFile(dir.file("p.las")), test::readFile(dir.file("q.las")));
}

}  // namespace
}  // namespace lodforge
