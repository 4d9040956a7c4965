#include "lodforge/generate/surface_samples.h"

#include <gtest/gtest.h>

#include <cmath>

#include "lodforge/core/distance.h"
#include "lodforge/core/threads.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/model_io.h"
#include "test_support.h"

namespace lodforge {
namespace {

// Two triangles side by side in z = 0, of areas 1 and 3, facing +z.
Model twoTriangles() {
  Model m;
  m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 1, 0}, {2, 0, 0}, {8, 0, 0}, {2, 1, 0}};
  m.indices = {0, 1, 2, 3, 4, 5};
  m.objects.push_back({});
  m.objects.back().vertexCount = 6;
  m.objects.back().triangleCount = 2;
  return m;
}

Model readOrFail(const std::string& path) {
  Result<Model> model = readModel(path);
  EXPECT_TRUE(model.ok()) << model.error().message;
  return model.ok() ? std::move(*model) : Model{};
}

TEST(SurfaceSamples, LieOnTheScanWithItsNormalsAndExactCount) {
  test::TempDir dir;
  const Model horse = readOrFail(test::dataPath("meshes/horse.ply"));
  ASSERT_GT(horse.triangleCount(), 0u);
  Result<GenerateStats> stats =
      sampleSurface(horse, {.points = 50'001, .seed = 4}, dir.file("s.ply"));
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  const Model cloud = readOrFail(dir.file("s.ply"));
  EXPECT_EQ(cloud.vertexCount(), 50'001u);
  EXPECT_EQ(cloud.triangleCount(), 0u);
  ASSERT_TRUE(cloud.hasNormals());
  for (const Vec3f& n : cloud.normals) ASSERT_NEAR(length(n), 1.0f, 1e-5f);
  // No noise: every point on the surface (float rounding of a ~0.2 model).
  std::vector<Vec3f> points;
  for (const Vec3f& p : cloud.positions)
    points.push_back(toFloat(toDouble(p) + cloud.origin - horse.origin));
  EXPECT_LT(farthestDistance(points, horse.positions, horse.indices), 1e-7);
}

TEST(SurfaceSamples, SpreadByAreaWithFaceNormalsAndGaussianNoise) {
  test::TempDir dir;
  const Model m = twoTriangles();
  const double diagonal = std::sqrt(8.0 * 8.0 + 1.0);
  ASSERT_TRUE(
      sampleSurface(m, {.points = 200'000, .seed = 9, .noise = 0.001}, dir.file("s.ply")).ok());
  const Model cloud = readOrFail(dir.file("s.ply"));
  std::uint64_t onSmall = 0;
  double sumSquares = 0, sum = 0;
  for (std::size_t i = 0; i < cloud.vertexCount(); ++i) {
    const Vec3d p = toDouble(cloud.positions[i]) + cloud.origin;
    if (p.x < 2) ++onSmall;
    ASSERT_EQ(cloud.normals[i].z, 1.0f);  // the faces' own normal: the mesh has none
    sumSquares += p.z * p.z;
    sum += p.z;
  }
  // One point in four on the triangle of area 1 (σ of the share: 0.001).
  EXPECT_NEAR(static_cast<double>(onSmall) / 200'000.0, 0.25, 0.005);
  // Offsets along the normal with the asked standard deviation and mean 0.
  const double sigma = std::sqrt(sumSquares / 200'000.0);
  EXPECT_NEAR(sigma, 0.001 * diagonal, 0.02 * 0.001 * diagonal);
  EXPECT_NEAR(sum / 200'000.0, 0.0, 0.01 * 0.001 * diagonal);
}

// A georeferenced mesh (an origin far from zero) gives points where the mesh is.
TEST(SurfaceSamples, AMeshWithAnOriginKeepsItsPlace) {
  test::TempDir dir;
  Model m = twoTriangles();
  m.origin = {1e6, 2e6, 0};
  ASSERT_TRUE(sampleSurface(m, {.points = 1'000, .seed = 2}, dir.file("s.ply")).ok());
  const Model cloud = readOrFail(dir.file("s.ply"));
  ASSERT_EQ(cloud.vertexCount(), 1'000u);
  for (const Vec3f& p : cloud.positions) {
    const Vec3d q = toDouble(p) + cloud.origin - m.origin;
    ASSERT_GE(q.x, -1e-3);
    ASSERT_LE(q.x, 8 + 1e-3);
    ASSERT_GE(q.y, -1e-3);
    ASSERT_LE(q.y, 1 + 1e-3);
    ASSERT_NEAR(q.z, 0.0, 1e-3);
  }
}

TEST(SurfaceSamples, DeterministicWhateverTheThreadCountAndSeeded) {
  test::TempDir dir;
  const Model m = twoTriangles();
  {
    const ThreadLimit one(1);
    ASSERT_TRUE(
        sampleSurface(m, {.points = 70'000, .seed = 5, .noise = 0.01}, dir.file("1.ply")).ok());
  }
  ASSERT_TRUE(
      sampleSurface(m, {.points = 70'000, .seed = 5, .noise = 0.01}, dir.file("2.ply")).ok());
  ASSERT_TRUE(
      sampleSurface(m, {.points = 70'000, .seed = 6, .noise = 0.01}, dir.file("3.ply")).ok());
  EXPECT_EQ(test::readFile(dir.file("1.ply")), test::readFile(dir.file("2.ply")));
  EXPECT_NE(test::readFile(dir.file("1.ply")), test::readFile(dir.file("3.ply")));
}

TEST(SurfaceSamples, RefusesAMeshWithoutAreaAndNegativeNoise) {
  test::TempDir dir;
  Model flat = twoTriangles();
  for (Vec3f& p : flat.positions) p.y = 0;  // both triangles collapse to segments
  Result<GenerateStats> none = sampleSurface(flat, {.points = 10}, dir.file("a.ply"));
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().kind, ErrorKind::kBadInput);
  Result<GenerateStats> negative =
      sampleSurface(twoTriangles(), {.points = 10, .noise = -1}, dir.file("b.ply"));
  ASSERT_FALSE(negative.ok());
  EXPECT_EQ(negative.error().kind, ErrorKind::kUsage);
}

}  // namespace
}  // namespace lodforge
