#include "lodforge/simplify/builder.h"

#include <gtest/gtest.h>

#include "lodforge/core/instances.h"
#include "lodforge/generate/cad.h"
#include "lodforge/io/cad/cad_reader.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/mesh/gltf_reader.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "lodforge/simplify/extract.h"
#include "lodforge/simplify/package.h"
#include "test_support.h"

namespace lodforge {
namespace {

TEST(Builder, StreamedPlyAndLoadedGlbGiveTheSamePackageContent) {
  test::TempDir dir;
  ASSERT_TRUE(generateCad({.objects = 500, .seed = 9}, dir.file("a.glb")).ok());
  ASSERT_TRUE(generateCad({.objects = 500, .seed = 9}, dir.file("a.ply")).ok());
  // Each object on its own: the PLY's float world positions lose some repeats that the GLB's
  // shared meshes keep, and a placed object has its shape's triangle order.
  BuildOptions own;
  own.placeRepeatedShapes = false;
  Result<BuildStats> fromPly = buildPackage(dir.file("a.ply"), dir.file("ply.lfp"), own);
  Result<BuildStats> fromGlb = buildPackage(dir.file("a.glb"), dir.file("glb.lfp"), own);
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
  // The shape cache gets an eighth of the limit, so a small limit keeps fewer shapes and builds
  // more repeats anew: the package is the same either way without it.
  BuildOptions small;
  small.memoryLimit = 56 << 20;  // 48 MiB fixed + 8 MiB: a few parts at a time
  small.placeRepeatedShapes = false;
  Result<BuildStats> waves = buildPackage(dir.file("a.ply"), dir.file("a.lfp"), small);
  ASSERT_TRUE(waves.ok()) << waves.error().message;
  EXPECT_GT(waves->waves, 3u);
  BuildOptions unlimited;
  unlimited.placeRepeatedShapes = false;
  Result<BuildStats> oneWave = buildPackage(dir.file("a.ply"), dir.file("b.lfp"), unlimited);
  ASSERT_TRUE(oneWave.ok());
  EXPECT_EQ(oneWave->waves, 1u);
  EXPECT_TRUE(test::readFile(dir.file("a.lfp")) == test::readFile(dir.file("b.lfp")))
      << "the package depends on the memory limit";

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

// How many objects are written with a mesh of their own (findPlacements places the others).
std::size_t distinctMeshes(const Model& model) {
  std::size_t own = 0;
  const std::vector<Placement> placements = findPlacements(model);
  for (std::size_t o = 0; o < placements.size(); ++o) own += placements[o].source == o ? 1 : 0;
  return own;
}

// 2CylinderEngine places 29 meshes 67 times. The builder simplifies each shape once: a placed
// object's levels are its shape's (same triangles, collapses and errors) and it sits where its
// input does. Across waves too (a small memory limit).
TEST(Builder, AShapePlacedAgainIsBuiltOnceAndSitsWhereItsInputDoes) {
  const std::string input = test::dataPath("meshes/2CylinderEngine.glb");
  Result<Model> source = readGltf(input);
  ASSERT_TRUE(source.ok());
  const std::vector<Placement> expected = findPlacements(*source);
  const std::size_t repeats = source->objectCount() - distinctMeshes(*source);
  ASSERT_GT(repeats, 30u);
  test::TempDir dir;
  // A small limit: several waves, and a shape cache (an eighth of it) that holds only some
  // shapes, so fewer repeats are placed, from whichever kept shape they fit.
  BuildOptions small;
  small.memoryLimit = 80 << 20;
  for (const bool limited : {false, true}) {
    Result<BuildStats> stats =
        buildPackage(input, dir.file("e.lfp"), limited ? small : BuildOptions{});
    ASSERT_TRUE(stats.ok()) << stats.error().message;
    if (limited) {
      EXPECT_GT(stats->waves, 1u);
      EXPECT_GT(stats->placements, 0u);
      EXPECT_LT(stats->placements, repeats);
    } else {
      EXPECT_EQ(stats->placements, repeats);
    }
    Result<Package> package = Package::open(dir.file("e.lfp"));
    ASSERT_TRUE(package.ok());
    const Model full = extractModel(*package, vertexCountsForRatio(*package, 1.0));
    for (std::size_t o = 0; o < source->objectCount(); ++o) {
      const std::size_t s = expected[o].source;
      if (s != o && !limited) {
        EXPECT_TRUE(std::ranges::equal(package->triangles(o), package->triangles(s))) << o;
        EXPECT_TRUE(std::ranges::equal(package->ecol(o), package->ecol(s))) << o;
        EXPECT_TRUE(std::ranges::equal(package->error(o), package->error(s))) << o;
      }
      // Every extracted vertex is an input vertex (the welded full detail), within the fit.
      const auto in = source->objectPositions(o);
      const double tolerance = 1e-5 * length(toDouble(source->objects[o].bounds.size())) + 1e-5;
      for (const Vec3f& p : full.objectPositions(o)) {
        double nearest = 1e30;
        for (const Vec3f& q : in) nearest = std::min(nearest, length(toDouble(p) - toDouble(q)));
        ASSERT_LE(nearest, tolerance) << "object " << o << (limited ? " (limited)" : "");
      }
    }
  }
  BuildOptions own;
  own.placeRepeatedShapes = false;
  Result<BuildStats> each = buildPackage(input, dir.file("own.lfp"), own);
  ASSERT_TRUE(each.ok());
  EXPECT_EQ(each->placements, 0u);
}

// `extract` writes a repeated shape once at any level: the extracted model's objects are the
// package's placements again.
TEST(Extract, InstancesComeBackAsOneMeshPerShapeAtEveryLevel) {
  const std::string input = test::dataPath("meshes/2CylinderEngine.glb");
  Result<Model> source = readGltf(input);
  ASSERT_TRUE(source.ok());
  test::TempDir dir;
  ASSERT_TRUE(buildPackage(input, dir.file("e.lfp")).ok());
  Result<Package> package = Package::open(dir.file("e.lfp"));
  ASSERT_TRUE(package.ok());
  for (const double ratio : {1.0, 0.5, 0.1, 0.0}) {
    const Model extracted = extractModel(*package, vertexCountsForRatio(*package, ratio));
    EXPECT_EQ(distinctMeshes(extracted), distinctMeshes(*source)) << ratio;
  }
  const Model byError = extractModel(*package, vertexCountsForError(*package, 0.5));
  EXPECT_EQ(distinctMeshes(byError), distinctMeshes(*source));
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

// CAD layers travel from a STEP assembly through the package to an extracted GLB (node extras)
// and back.
TEST(Extract, CadLayersComeBack) {
  test::TempDir dir;
  ASSERT_TRUE(generateCad({.objects = 40, .seed = 5}, dir.file("a.step")).ok());
  Result<Model> source = readCad(dir.file("a.step"));
  ASSERT_TRUE(source.ok()) << source.error().message;
  ASSERT_GT(source->layers.size(), 3u);  // the generator's kinds, each on its own layer
  ASSERT_TRUE(buildPackage(dir.file("a.step"), dir.file("a.lfp")).ok());
  Result<Package> package = Package::open(dir.file("a.lfp"));
  ASSERT_TRUE(package.ok()) << package.error().message;
  ASSERT_EQ(package->objectCount(), source->objectCount());
  EXPECT_EQ(package->layerCount(), source->layers.size());
  ASSERT_TRUE(
      writeGlb(extractModel(*package, vertexCountsForRatio(*package, 0.5)), dir.file("a.glb"))
          .ok());
  Result<Model> extracted = readGltf(dir.file("a.glb"));
  ASSERT_TRUE(extracted.ok());
  ASSERT_EQ(extracted->objectCount(), source->objectCount());
  std::size_t onLayers = 0;
  for (std::size_t o = 0; o < source->objectCount(); ++o) {
    EXPECT_EQ(package->objectLayer(o), source->objectLayer(o)) << o;
    EXPECT_EQ(extracted->objectLayer(o), source->objectLayer(o)) << o;
    onLayers += source->objectLayer(o).empty() ? 0 : 1;
  }
  EXPECT_EQ(onLayers, source->objectCount());
}

// A package keeps each object's assembly path and material, and `extract` hangs the objects back
// in that tree with those materials: the GLB read again names the same paths. (2CylinderEngine's
// materials are single-sided and stay so.)
TEST(Extract, TheAssemblyTreeAndMaterialsComeBack) {
  const std::string input = test::dataPath("meshes/2CylinderEngine.glb");
  Result<Model> source = readGltf(input);
  ASSERT_TRUE(source.ok());
  test::TempDir dir;
  ASSERT_TRUE(buildPackage(input, dir.file("e.lfp")).ok());
  Result<Package> package = Package::open(dir.file("e.lfp"));
  ASSERT_TRUE(package.ok());
  ASSERT_TRUE(
      writeGlb(extractModel(*package, vertexCountsForRatio(*package, 0.5)), dir.file("e.glb"))
          .ok());
  Result<Model> extracted = readGltf(dir.file("e.glb"));
  ASSERT_TRUE(extracted.ok());
  ASSERT_EQ(extracted->objectCount(), source->objectCount());
  std::size_t withMaterial = 0;
  for (std::size_t o = 0; o < source->objectCount(); ++o) {
    // The same groups above the object's own node (named as the object is). The path's first
    // component is the root node when all objects share it, else under a new "root".
    const std::string_view path = source->objectPath(o);
    const std::string expected =
        std::string(path.substr(0, path.rfind('/') + 1)) + std::string(source->objectName(o));
    EXPECT_TRUE(extracted->objectPath(o) == expected ||
                extracted->objectPath(o) == "root/" + expected)
        << extracted->objectPath(o) << " for " << expected;
    EXPECT_NE(path.find('/'), std::string_view::npos);
    EXPECT_EQ(extracted->objectName(o), source->objectName(o));
    const std::uint32_t was = source->objects[o].material, is = extracted->objects[o].material;
    ASSERT_EQ(was == kNoMaterial, is == kNoMaterial) << o;
    if (was == kNoMaterial) continue;
    ++withMaterial;
    const Material &a = source->materials[was], &b = extracted->materials[is];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.alphaMode, b.alphaMode);
    EXPECT_EQ(a.metallic, b.metallic);
    EXPECT_EQ(a.roughness, b.roughness);
    EXPECT_EQ(a.emissive, b.emissive);
    EXPECT_EQ(a.doubleSided, b.doubleSided);
  }
  EXPECT_EQ(withMaterial, source->objectCount());
  // Written and read once more, the tree is stable: the shared "root" is the root node again.
  ASSERT_TRUE(writeGlb(*extracted, dir.file("again.glb")).ok());
  Result<Model> again = readGltf(dir.file("again.glb"));
  ASSERT_TRUE(again.ok());
  for (std::size_t o = 0; o < again->objectCount(); ++o)
    EXPECT_EQ(again->objectPath(o), extracted->objectPath(o));
}

}  // namespace
}  // namespace lodforge
