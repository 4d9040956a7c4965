#include "lodforge/generate/scan.h"

#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

Model generateAndRead(std::uint64_t triangles, std::uint64_t seed, const test::TempDir& dir) {
  const std::string path = dir.file(fmt::format("scan-{}-{}.ply", triangles, seed));
  Result<GenerateStats> stats = generateScan({.triangles = triangles, .seed = seed}, path);
  EXPECT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_EQ(stats->triangles, triangles);
  Result<Model> model = readPly(path);
  EXPECT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->vertexCount(), stats->vertices);
  return std::move(model.value());
}

TEST(Scan, ExactTriangleCountsAndEveryVertexUsed) {
  test::TempDir dir;
  for (std::uint64_t n : {1ull, 2ull, 3ull, 7ull, 1000ull, 12345ull, 100001ull}) {
    const Model model = generateAndRead(n, 1, dir);
    EXPECT_EQ(model.triangleCount(), n);
    std::vector<std::uint32_t> remap(model.vertexCount());
    EXPECT_EQ(findReferencedVertices(std::uint32_t(model.vertexCount()), model.indices, remap),
              model.vertexCount())
        << n;
  }
}

TEST(Scan, OneConnectedSurfaceWithHolesAndAnOverhang) {
  test::TempDir dir;
  const Model model = generateAndRead(200'000, 2, dir);
  std::vector<std::uint32_t> labels(model.triangleCount());
  EXPECT_EQ(connectedComponents(std::uint32_t(model.vertexCount()), model.indices, labels), 1u);
  // Boundary edges: the outer rim of a ~365 x 274 cell grid is ~1,280 edges; holes add more.
  const std::uint64_t boundary = countBoundaryEdges(model.indices);
  EXPECT_GT(boundary, 1400u);
  // Overhang: some triangles face downwards.
  std::uint64_t down = 0;
  for (std::size_t t = 0; t < model.triangleCount(); ++t) {
    const auto& p = model.positions;
    const auto& i = model.indices;
    if (cross(p[i[3 * t + 1]] - p[i[3 * t]], p[i[3 * t + 2]] - p[i[3 * t]]).z < 0) ++down;
  }
  EXPECT_GT(down, 100u);
  EXPECT_LT(down, model.triangleCount() / 10);
  EXPECT_TRUE(model.hasNormals());
  EXPECT_TRUE(model.hasColors());
}

TEST(Scan, SameSeedSameFileOtherSeedOtherFile) {
  test::TempDir dir;
  ASSERT_TRUE(generateScan({.triangles = 5000, .seed = 9}, dir.file("a.ply")).ok());
  ASSERT_TRUE(generateScan({.triangles = 5000, .seed = 9}, dir.file("b.ply")).ok());
  ASSERT_TRUE(generateScan({.triangles = 5000, .seed = 10}, dir.file("c.ply")).ok());
  EXPECT_EQ(test::readFile(dir.file("a.ply")), test::readFile(dir.file("b.ply")));
  EXPECT_NE(test::readFile(dir.file("a.ply")), test::readFile(dir.file("c.ply")));
}

TEST(Scan, RefusesOtherFormatsAndZeroTriangles) {
  test::TempDir dir;
  EXPECT_EQ(generateScan({.triangles = 10}, dir.file("s.glb")).error().kind, ErrorKind::kUsage);
  EXPECT_EQ(generateScan({.triangles = 0}, dir.file("s.ply")).error().kind, ErrorKind::kUsage);
}

}  // namespace
}  // namespace lodforge
