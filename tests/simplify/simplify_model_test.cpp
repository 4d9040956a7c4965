#include "lodforge/simplify/simplify_model.h"

#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "lodforge/core/distance.h"
#include "lodforge/io/model_io.h"
#include "test_support.h"

namespace lodforge {
namespace {

using VertexKey = std::tuple<float, float, float, float, float>;  // position, texture coordinate

std::set<VertexKey> verticesOf(const Model& model, std::size_t o) {
  std::set<VertexKey> out;
  const ObjectRecord& object = model.objects[o];
  for (std::uint32_t v = 0; v < object.vertexCount; ++v) {
    const Vec3f p = model.positions[object.vertexOffset + v];
    const Vec2f t = model.uvs[object.vertexOffset + v];
    out.emplace(p.x, p.y, p.z, t.x, t.y);
  }
  return out;
}

// The spider (19 textured objects) to 30 %: every object keeps its material and name and no more
// than its share of triangles (or what it could not lose), and every vertex left is one of its
// own, position and texture coordinate together: nothing is interpolated or taken from another
// chart. The surface stays within the error the simplifier records.
TEST(SimplifyModel, KeepsWedgesAsTheyWereAndReachesItsShare) {
  Result<Model> spider = readModel(test::dataPath("textured/spider/spider.obj"));
  ASSERT_TRUE(spider.ok());
  Model simplified = *spider;
  const ModelSimplifyStats stats = simplifyModel(simplified, 0.3);
  ASSERT_EQ(simplified.objectCount(), spider->objectCount());
  EXPECT_EQ(stats.trianglesBefore, spider->triangleCount());
  EXPECT_EQ(stats.trianglesAfter, simplified.triangleCount());
  EXPECT_LT(simplified.triangleCount(), spider->triangleCount() / 2);
  EXPECT_EQ(simplified.images.size(), spider->images.size());
  ASSERT_EQ(simplified.uvs.size(), simplified.positions.size());
  for (std::size_t o = 0; o < spider->objectCount(); ++o) {
    EXPECT_EQ(simplified.objectName(o), spider->objectName(o));
    EXPECT_EQ(simplified.objects[o].material, spider->objects[o].material);
    const std::set<VertexKey> before = verticesOf(*spider, o), after = verticesOf(simplified, o);
    for (const VertexKey& v : after) EXPECT_EQ(before.count(v), 1u) << "object " << o;
    for (std::uint32_t i : simplified.objectIndices(o))
      EXPECT_LT(i, simplified.objects[o].vertexCount);
  }
  std::vector<std::uint32_t> a, b;
  for (std::size_t o = 0; o < spider->objectCount(); ++o) {
    for (std::uint32_t i : spider->objectIndices(o))
      a.push_back(static_cast<std::uint32_t>(spider->objects[o].vertexOffset) + i);
    for (std::uint32_t i : simplified.objectIndices(o))
      b.push_back(static_cast<std::uint32_t>(simplified.objects[o].vertexOffset) + i);
  }
  const double hausdorff = sampledHausdorff(spider->positions, a, simplified.positions, b, 20'000);
  EXPECT_GT(stats.error, 0);
  EXPECT_LE(hausdorff, 2.5 * stats.error) << hausdorff << " against " << stats.error;
}

}  // namespace
}  // namespace lodforge
