#include "lodforge/generate/points.h"

#include <gtest/gtest.h>

#include "lodforge/core/threads.h"
#include "lodforge/io/ply_reader.h"
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

}  // namespace
}  // namespace lodforge
