#include "lodforge/core/model.h"

#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"

namespace lodforge {
namespace {

Model twoObjects() {
  Model model;
  ModelBuilder builder(model);
  builder.beginObject("first");
  for (Vec3f p : {Vec3f{0, 0, 0}, Vec3f{1, 0, 0}, Vec3f{0, 1, 0}}) builder.addVertex(p);
  builder.addTriangle(0, 1, 2);
  builder.beginObject("second part");
  for (Vec3f p : {Vec3f{5, 5, 5}, Vec3f{6, 5, 5}, Vec3f{5, 6, 5}, Vec3f{6, 6, 7}})
    builder.addVertex(p);
  builder.addTriangle(0, 1, 2);
  builder.addTriangle(1, 3, 2);
  builder.endObject();
  return model;
}

TEST(ModelBuilder, KeepsOffsetsNamesAndBounds) {
  const Model model = twoObjects();
  ASSERT_EQ(model.objectCount(), 2u);
  EXPECT_EQ(model.vertexCount(), 7u);
  EXPECT_EQ(model.triangleCount(), 3u);
  EXPECT_EQ(model.objectName(0), "first");
  EXPECT_EQ(model.objectName(1), "second part");
  EXPECT_EQ(model.objects[1].vertexOffset, 3u);
  EXPECT_EQ(model.objects[1].triangleOffset, 1u);
  EXPECT_EQ(model.objects[1].vertexCount, 4u);
  EXPECT_EQ(model.objects[1].triangleCount, 2u);
  EXPECT_EQ(model.objects[1].bounds.min, (Vec3f{5, 5, 5}));
  EXPECT_EQ(model.objects[1].bounds.max, (Vec3f{6, 6, 7}));
  EXPECT_EQ(model.bounds().min, (Vec3f{0, 0, 0}));
  EXPECT_EQ(model.objectIndices(1)[3], 1u);  // indices stay local to their object
  std::string why;
  EXPECT_TRUE(isConsistent(model, &why)) << why;
}

TEST(ModelBuilder, MemoryCountsEveryArray) {
  Model model = twoObjects();
  const std::uint64_t plain = model.memoryBytes();
  EXPECT_EQ(plain, 7 * 12 + 3 * 12 + 2 * sizeof(ObjectRecord) + model.names.size());
  model.normals.assign(7, Vec3f{0, 0, 1});
  model.colors.assign(7, Rgba8{});
  EXPECT_EQ(model.memoryBytes(), plain + 7 * 16);
}

TEST(Consistency, CatchesOutOfRangeIndicesAndGaps) {
  Model model = twoObjects();
  model.indices[0] = 3;  // object 0 has only 3 vertices
  std::string why;
  EXPECT_FALSE(isConsistent(model, &why));
  EXPECT_NE(why.find("out of range"), std::string::npos);
  model = twoObjects();
  model.normals.resize(2);
  EXPECT_FALSE(isConsistent(model));
  model = twoObjects();
  model.objects[1].vertexOffset = 4;
  EXPECT_FALSE(isConsistent(model));
}

TEST(Origin, StaysZeroNearTheOriginAndCentresFarAway) {
  Aabbd near;
  near.add(Vec3d{-100, -20, 0});
  near.add(Vec3d{300, 50, 10});
  EXPECT_EQ(chooseOrigin(near), Vec3d{});
  Aabbd utm;
  utm.add(Vec3d{637000.25, 5106000.5, 120});
  utm.add(Vec3d{638000.75, 5107000.5, 180});
  const Vec3d origin = chooseOrigin(utm);
  EXPECT_EQ(origin, (Vec3d{637501, 5106501, 150}));  // centre rounded half away from zero
  // Offsets from it fit floats with millimetre precision.
  const float offset = static_cast<float>(638000.75 - origin.x);
  EXPECT_NEAR(origin.x + offset, 638000.75, 1e-4);
}

TEST(WeldModel, WeldsInsideObjectsButNeverAcross) {
  Model model;
  ModelBuilder builder(model);
  // Two objects, each a quad as a soup of 2 triangles (6 vertices), sharing an edge in space.
  for (float x : {0.0f, 1.0f}) {
    builder.beginObject("quad");
    for (Vec3f p : {Vec3f{x, 0, 0}, Vec3f{x + 1, 0, 0}, Vec3f{x + 1, 1, 0}, Vec3f{x, 0, 0},
                    Vec3f{x + 1, 1, 0}, Vec3f{x, 1, 0}}) {
      builder.addVertex(p);
    }
    builder.addTriangle(0, 1, 2);
    builder.addTriangle(3, 4, 5);
  }
  builder.endObject();
  model.layers = {"structure"};  // a CAD layer stays with its object
  model.objects[1].layer = 0;
  weldModel(model, {});
  ASSERT_EQ(model.layers, std::vector<std::string>{"structure"});
  EXPECT_EQ(model.objectLayer(0), "");
  EXPECT_EQ(model.objectLayer(1), "structure");
  EXPECT_EQ(model.objects[0].vertexCount, 4u);
  EXPECT_EQ(model.objects[1].vertexCount, 4u);
  EXPECT_EQ(model.vertexCount(), 8u);
  EXPECT_EQ(model.triangleCount(), 4u);
  EXPECT_TRUE(isConsistent(model));
}

TEST(WeldModel, DropsTrianglesThatCollapse) {
  Model model;
  ModelBuilder builder(model);
  builder.beginObject("sliver");
  for (Vec3f p : {Vec3f{0, 0, 0}, Vec3f{1, 0, 0}, Vec3f{1.0f + 1e-6f, 0, 0}, Vec3f{0, 1, 0}})
    builder.addVertex(p);
  builder.addTriangle(0, 1, 2);  // becomes (0, 1, 1) once 1 and 2 weld
  builder.addTriangle(0, 1, 3);
  builder.endObject();
  WeldOptions options;
  options.epsilon = 1e-3f;
  weldModel(model, options);
  EXPECT_EQ(model.triangleCount(), 1u);
  EXPECT_EQ(model.vertexCount(), 3u);
}

}  // namespace
}  // namespace lodforge
