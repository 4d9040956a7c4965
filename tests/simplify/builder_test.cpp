#include "lodforge/simplify/builder.h"

#include <gtest/gtest.h>

#include "lodforge/generate/cad.h"
#include "lodforge/io/ply_writer.h"
#include "lodforge/simplify/extract.h"
#include "lodforge/simplify/package.h"
#include "test_support.h"

namespace lodforge {
namespace {

TEST(Builder, StreamedPlyAndLoadedGlbGiveTheSamePackageContent) {
  test::TempDir dir;
  ASSERT_TRUE(generateCad({.objects = 500, .seed = 9}, dir.file("a.glb")).ok());
  ASSERT_TRUE(generateCad({.objects = 500, .seed = 9}, dir.file("a.ply")).ok());
  Result<BuildStats> fromPly = buildPackage(dir.file("a.ply"), dir.file("ply.lfp"));
  Result<BuildStats> fromGlb = buildPackage(dir.file("a.glb"), dir.file("glb.lfp"));
  ASSERT_TRUE(fromPly.ok()) << fromPly.error().message;
  ASSERT_TRUE(fromGlb.ok()) << fromGlb.error().message;
  EXPECT_TRUE(fromPly->streamed);
  EXPECT_FALSE(fromGlb->streamed);
  EXPECT_EQ(fromPly->objects, 500u);
  EXPECT_EQ(fromPly->triangles, fromGlb->triangles);
  EXPECT_EQ(fromPly->vertices, fromGlb->vertices);
  Result<Package> a = Package::open(dir.file("ply.lfp")), b = Package::open(dir.file("glb.lfp"));
  ASSERT_TRUE(a.ok() && b.ok());
  for (std::size_t o = 0; o < 500; ++o) {
    ASSERT_EQ(a->object(o).vertexCount, b->object(o).vertexCount) << o;
    ASSERT_EQ(a->object(o).minVertexCount, b->object(o).minVertexCount) << o;
    ASSERT_TRUE(std::equal(a->triangles(o).begin(), a->triangles(o).end(), b->triangles(o).begin()))
        << o;
  }
}

TEST(Builder, UngroupedPlyFallsBackToLoading) {
  // Faces of objects 0 and 1 interleaved: it cannot stream, but it still builds.
  test::TempDir dir;
  PlyLayout layout;
  layout.vertexCount = 8;
  layout.faceCount = 4;
  layout.objectIds = true;
  Result<PlyWriter> writer = PlyWriter::create(dir.file("mixed.ply"), layout);
  ASSERT_TRUE(writer.ok());
  const std::vector<Vec3f> quadA = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const std::vector<Vec3f> quadB = {{5, 0, 0}, {6, 0, 0}, {6, 1, 0}, {5, 1, 0}};
  ASSERT_TRUE(writer->writeVertices(quadA, {}, {}).ok());
  ASSERT_TRUE(writer->writeVertices(quadB, {}, {}).ok());
  ASSERT_TRUE(writer
                  ->writeTriangles(std::vector<std::uint32_t>{0, 1, 2, 4, 5, 6, 0, 2, 3, 4, 6, 7},
                                   std::vector<std::uint32_t>{0, 1, 0, 1})
                  .ok());
  ASSERT_TRUE(writer->finish().ok());
  Result<BuildStats> stats = buildPackage(dir.file("mixed.ply"), dir.file("mixed.lfp"));
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_FALSE(stats->streamed);
  EXPECT_EQ(stats->objects, 2u);
  EXPECT_EQ(stats->triangles, 4u);
}

TEST(Builder, MemoryLimitSplitsTheWorkIntoWavesOrRefusesAHugeObject) {
  test::TempDir dir;
  ASSERT_TRUE(generateCad({.objects = 400, .seed = 2}, dir.file("a.ply")).ok());
  BuildOptions small;
  small.memoryLimit = 56 << 20;  // 48 MiB fixed + 8 MiB: a few parts at a time
  Result<BuildStats> waves = buildPackage(dir.file("a.ply"), dir.file("a.lfp"), small);
  ASSERT_TRUE(waves.ok()) << waves.error().message;
  EXPECT_GT(waves->waves, 3u);
  Result<BuildStats> oneWave = buildPackage(dir.file("a.ply"), dir.file("b.lfp"));
  ASSERT_TRUE(oneWave.ok());
  EXPECT_EQ(oneWave->waves, 1u);
  EXPECT_EQ(test::readFile(dir.file("a.lfp")),
            test::readFile(dir.file("b.lfp")));  // same package either way

  BuildOptions tiny;
  tiny.memoryLimit = 52 << 20;  // 4 MiB for objects; the horse needs ~20 MiB
  Result<BuildStats> refused =
      buildPackage(test::dataPath("meshes/horse.ply"), dir.file("h.lfp"), tiny);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().kind, ErrorKind::kLimit);
  EXPECT_NE(refused.error().message.find("needs about"), std::string::npos)
      << refused.error().message;
  EXPECT_FALSE(std::filesystem::exists(dir.file("h.lfp")));
  tiny.memoryLimit = 1 << 20;
  refused = buildPackage(test::dataPath("meshes/horse.ply"), dir.file("h.lfp"), tiny);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("too small to build anything"), std::string::npos);
  EXPECT_TRUE(test::listFolder(dir.path()).size() == 3);  // a.ply, a.lfp, b.lfp: no temporaries
}

TEST(Extract, RatiosAndErrorsPickTheExpectedLevels) {
  test::TempDir dir;
  ASSERT_TRUE(buildPackage(test::dataPath("meshes/stanford-bunny.obj"), dir.file("b.lfp")).ok());
  Result<Package> package = Package::open(dir.file("b.lfp"));
  ASSERT_TRUE(package.ok());
  const PackageObject& o = package->object(0);
  const Model full = extractModel(*package, vertexCountsForRatio(*package, 1.0));
  EXPECT_EQ(full.triangleCount(), o.triangleCount);
  EXPECT_EQ(full.vertexCount(), o.vertexCount);
  const Model simplest = extractModel(*package, vertexCountsForRatio(*package, 0.0));
  EXPECT_EQ(simplest.vertexCount(), o.minVertexCount);
  EXPECT_EQ(simplest.triangleCount(), o.minTriangleCount);
  const Model tenth = extractModel(*package, vertexCountsForRatio(*package, 0.1));
  EXPECT_NEAR(double(tenth.vertexCount()), 0.1 * o.vertexCount, 1.0);
  EXPECT_TRUE(isConsistent(tenth));
  // By error: the result's recorded error is within the bound, one vertex fewer is not.
  const float bound = package->error(0)[(o.vertexCount - o.minVertexCount) / 2];
  const std::uint32_t n = vertexCountsForError(*package, bound)[0];
  EXPECT_LE(package->error(0)[n - o.minVertexCount], bound);
  EXPECT_TRUE(n == o.minVertexCount || package->error(0)[n - 1 - o.minVertexCount] > bound);
}

}  // namespace
}  // namespace lodforge
