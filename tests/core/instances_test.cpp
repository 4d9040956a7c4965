// Repeated meshes found again in a model of world positions (core/instances.h): the rigid fit on
// random point sets moved by random motions, and real assemblies written once per shape.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>

#include "lodforge/core/instances.h"
#include "lodforge/core/random.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/model_io.h"
#include "rigid_support.h"
#include "test_support.h"

namespace lodforge {
namespace {

using test::moved;
using test::randomMotion;
using test::randomPoints;

TEST(GlbInstances, ARigidMotionIsFoundAndNothingElse) {
  Random random(20261126);
  for (int trial = 0; trial < 200; ++trial) {
    const std::vector<Vec3f> points = randomPoints(random, 3 + trial % 40);
    const Mat4d motion = randomMotion(random);
    const std::vector<Vec3f> target = moved(motion, points);
    const auto found = fitRigidMotion(points, target, 1e-5);
    ASSERT_TRUE(found) << trial;
    for (int k = 0; k < 16; ++k) EXPECT_NEAR(found->m[k], motion.m[k], 1e-4) << trial;
    // A mirror image (of points not in one plane), a scaled copy and one vertex moved by 10× the
    // tolerance are not motions.
    const Mat4d mirror = motion * Mat4d::scale({-1, 1, 1});
    if (points.size() > 3) {
      EXPECT_FALSE(fitRigidMotion(points, moved(mirror, points), 1e-5)) << trial;
    }
    EXPECT_FALSE(
        fitRigidMotion(points, moved(motion * Mat4d::scale({1.001, 1.001, 1.001}), points), 1e-5))
        << trial;
    // The bent vertex is not one of the three the frame is built from (those fit by
    // construction): with more than three points, the last one is free of them in most trials,
    // and any vertex moved off the fitted motion by 10× the tolerance fails.
    std::vector<Vec3f> bent = target;
    bent[trial % bent.size()] += Vec3f{1e-4f, 1e-4f, 1e-4f};
    EXPECT_FALSE(fitRigidMotion(points, bent, 1e-5)) << trial;
  }
  // Points on a line span no frame.
  const std::vector<Vec3f> line{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  EXPECT_FALSE(fitRigidMotion(line, line, 1e-5));
}

nlohmann::json glbJson(const std::string& path) {
  const std::string bytes = test::readFile(path);
  std::uint32_t jsonLength = 0;
  std::memcpy(&jsonLength, bytes.data() + 12, 4);
  return nlohmann::json::parse(bytes.substr(20, jsonLength));
}

// Every object of `back` lies where the object of `source` with its name and place in the tree
// lies, to `tolerance` (the node tree may list the objects in another order).
void expectSamePlaces(const Model& source, const Model& back, double tolerance) {
  ASSERT_EQ(back.objectCount(), source.objectCount());
  ASSERT_EQ(back.vertexCount(), source.vertexCount());
  // Objects with one path (a part placed twice under one parent) keep their order; the writer
  // may have added a "root" above them all.
  std::map<std::string, std::vector<std::size_t>> byPath;
  for (std::size_t o = back.objectCount(); o-- > 0;)
    byPath[std::string(back.objectPath(o))].push_back(o);
  for (std::size_t s = 0; s < source.objectCount(); ++s) {
    const std::string_view path = source.objectPath(s);
    const std::string key =
        std::string(path.substr(0, path.rfind('/') + 1)) + std::string(source.objectName(s));
    auto found = byPath.find(key);
    if (found == byPath.end()) found = byPath.find("root/" + key);
    ASSERT_TRUE(found != byPath.end() && !found->second.empty()) << key;
    const std::size_t o = found->second.back();
    found->second.pop_back();
    const auto a = source.objectPositions(s), b = back.objectPositions(o);
    ASSERT_EQ(a.size(), b.size()) << path;
    for (std::size_t v = 0; v < a.size(); ++v) {
      const Vec3d wa = toDouble(a[v]) + source.origin;
      const Vec3d wb = toDouble(b[v]) + back.origin;
      ASSERT_LT(length(wa - wb), tolerance) << path << " vertex " << v;
    }
  }
}

// A flat quad moved, or mirrored (for a flat mesh that is a half turn, fronts included), is the
// quad placed again; with its vertex normals turned over it is not.
TEST(GlbInstances, FlatMeshesAndTheirNormals) {
  const std::vector<Vec3f> quad{{0, 0, 0}, {1, 0, 0}, {1, 2, 0}, {0, 2, 0}};
  const auto model = [&](auto at, float otherNormal) {
    Model m;
    ModelBuilder builder(m);
    for (int object = 0; object < 2; ++object) {
      builder.beginObject(object == 0 ? "quad" : "other");
      for (const Vec3f& p : quad) builder.addVertex(object == 0 ? p : at(p));
      builder.addTriangle(0, 1, 2);
      builder.addTriangle(0, 2, 3);
      builder.endObject();
    }
    m.normals.assign(4, Vec3f{0, 0, 1});
    m.normals.resize(8, Vec3f{0, 0, otherNormal});
    return m;
  };
  const auto moved = [](Vec3f p) { return Vec3f{p.x + 5, p.y, p.z}; };
  const auto mirrored = [](Vec3f p) { return Vec3f{40 - p.x, p.y, p.z}; };
  EXPECT_EQ(findPlacements(model(moved, 1))[1].source, 0u);
  EXPECT_EQ(findPlacements(model(moved, -1))[1].source, 1u);
  EXPECT_EQ(findPlacements(model(mirrored, -1))[1].source, 0u);  // the half turn turns normals
  EXPECT_EQ(findPlacements(model(mirrored, 1))[1].source, 1u);
}

// A 2 cm part placed 2 km from the origin rounds ~1e-4 there: its copy near the origin is still
// found, whichever of the two comes first (the search looks as far as the rounder one needs).
TEST(GlbInstances, AFarCopyAndANearOneAreFoundInEitherOrder) {
  Random random(4711);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<Vec3f> part = randomPoints(random, 30);
    for (Vec3f& p : part) p = p * 0.01f;
    Mat4d far = randomMotion(random), near = randomMotion(random);
    for (int row = 0; row < 3; ++row) {
      far.at(row, 3) = row == 0 ? 2000 : 0;
      near.at(row, 3) = 0.05 * row;
    }
    for (const bool farFirst : {true, false}) {
      Model model;
      ModelBuilder builder(model);
      for (const Mat4d& at : farFirst ? std::array{far, near} : std::array{near, far}) {
        builder.beginObject("part");
        for (const Vec3f& p : moved(at, part)) builder.addVertex(p);
        for (std::uint32_t t = 0; t + 2 < 30; ++t) builder.addTriangle(t, t + 1, t + 2);
        builder.endObject();
      }
      EXPECT_EQ(findPlacements(model)[1].source, 0u) << trial << (farFirst ? " far first" : "");
    }
  }
}

// 2CylinderEngine.glb places 29 meshes under 67 nodes; read (world positions) and written again
// it has its 29 meshes back, and read again every object lies where it lay, with its name.
TEST(GlbInstances, AGltfAssemblyIsWrittenOncePerMesh) {
  Result<Model> source = readModel(test::dataPath("meshes/2CylinderEngine.glb"));
  ASSERT_TRUE(source.ok()) << source.error().message;
  const std::vector<Placement> placements = findPlacements(*source);
  std::size_t sources = 0;
  for (std::size_t o = 0; o < placements.size(); ++o) sources += placements[o].source == o;
  EXPECT_EQ(sources, 29u);

  test::TempDir dir;
  const std::string shared = dir.file("shared.glb"), apart = dir.file("apart.glb");
  ASSERT_TRUE(writeGlb(*source, shared).ok());
  GlbWriteOptions options;
  options.shareMeshes = false;
  ASSERT_TRUE(writeGlb(*source, apart, options).ok());
  EXPECT_EQ(glbJson(shared)["meshes"].size(), 29u);
  EXPECT_EQ(glbJson(apart)["meshes"].size(), source->objectCount());
  EXPECT_LT(std::filesystem::file_size(shared), std::filesystem::file_size(apart) * 3 / 4);

  Result<Model> back = readModel(shared);
  ASSERT_TRUE(back.ok()) << back.error().message;
  expectSamePlaces(*source, *back, 1e-5 * length(toDouble(source->bounds().size())));
}

// A STEP shape placed several times comes out of the CAD reader as equal triangles in different
// places; written to GLB, each distinct shape is one mesh.
TEST(GlbInstances, CadInstancesShareTheirShapesMesh) {
  Result<Model> motor = readModel(test::dataPath("cad/as1_motor.step"));
  ASSERT_TRUE(motor.ok()) << motor.error().message;
  test::TempDir dir;
  ASSERT_TRUE(writeGlb(*motor, dir.file("motor.glb")).ok());
  const nlohmann::json json = glbJson(dir.file("motor.glb"));
  // 35 instances of 22 shapes (OCCT's count); two of the shapes mesh to the same triangles.
  EXPECT_LE(json["meshes"].size(), 22u);
  EXPECT_GE(json["meshes"].size(), 20u);
  Result<Model> back = readModel(dir.file("motor.glb"));
  ASSERT_TRUE(back.ok()) << back.error().message;
  expectSamePlaces(*motor, *back, 1e-5 * length(toDouble(motor->bounds().size())));
}

}  // namespace
}  // namespace lodforge
