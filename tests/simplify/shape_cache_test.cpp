// The builder's shape cache (shape_cache.h): a shape placed again is found with its motion, a
// mirror image or another size is not, the cache keeps no more than its bytes, and a placed
// progressive mesh is the kept one moved.
#include "lodforge/simplify/shape_cache.h"

#include <gtest/gtest.h>

#include "lodforge/generate/shapes.h"
#include "lodforge/simplify/prepare.h"
#include "rigid_support.h"

namespace lodforge {
namespace {

// A capped cylinder (a bolt shank), `scale` times its size, moved by `motion`.
SourceObject part(const Mat4d& motion, float scale = 1) {
  PartMesh mesh;
  addCylinderSide(mesh, 0.4f * scale, 0, 3 * scale, 24, 4, true);
  addDisk(mesh, 0.4f * scale, 3 * scale, 24, true);
  addDisk(mesh, 0.4f * scale, 0, 24, false);
  SourceObject object;
  object.name = "shank";
  object.positions = test::moved(motion, mesh.positions);
  for (const Vec3f& n : mesh.normals)
    object.normals.push_back(toFloat(motion.transformVector(toDouble(n))));
  object.colors.assign(mesh.positions.size(), Rgba8{200, 180, 40, 255});
  object.indices = mesh.indices;
  object.material = 3;
  return object;
}

constexpr std::uint64_t kRoom = std::uint64_t{64} << 20;

TEST(ShapeCache, FindsAShapeMovedRigidlyAndNotAMirrorOrAnotherSize) {
  Random random(20261126);
  for (int trial = 0; trial < 50; ++trial) {
    ShapeCache cache(kRoom);
    const Mat4d first = test::randomMotion(random), second = test::randomMotion(random);
    const ShapeLookup kept = cache.lookup(part(first));
    ASSERT_TRUE(kept.remembered && !kept.placed) << trial;
    const ShapeLookup again = cache.lookup(part(second));
    ASSERT_TRUE(again.placed && !again.remembered) << trial;
    EXPECT_EQ(again.placed->shape, *kept.remembered);
    // The found motion takes the first placement onto the second.
    const SourceObject a = part(first), b = part(second);
    for (std::size_t v = 0; v < a.positions.size(); v += 7)
      EXPECT_LT(length(again.placed->motion.transformPoint(toDouble(a.positions[v])) -
                       toDouble(b.positions[v])),
                1e-4)
          << trial;

    const ShapeLookup mirror = cache.lookup(part(Mat4d::scale({-1, 1, 1}) * first));
    EXPECT_FALSE(mirror.placed) << trial;
    // Scaled by 3e-5: the spread is within the search's reach, the fit turns it away.
    EXPECT_FALSE(cache.lookup(part(second, 1.00003f)).placed) << trial;
    SourceObject recoloured = part(second);
    recoloured.colors[5].r ^= 1;
    EXPECT_FALSE(cache.lookup(recoloured).placed) << trial;
    SourceObject otherMaterial = part(second);
    otherMaterial.material = 4;
    EXPECT_FALSE(cache.lookup(otherMaterial).placed) << trial;
    SourceObject turned = part(second);  // a normal turned away from the motion's
    turned.normals[7] = {turned.normals[7].y, turned.normals[7].z, turned.normals[7].x};
    EXPECT_FALSE(cache.lookup(turned).placed) << trial;
  }
}

TEST(ShapeCache, KeepsNoMoreThanItsBytesAndNothingWithoutRoom) {
  const SourceObject one = part(Mat4d{});
  ShapeCache none(0);
  EXPECT_FALSE(none.lookup(one).remembered);
  EXPECT_FALSE(none.lookup(part(Mat4d::translation({5, 0, 0}))).placed);

  // What one shape takes, then room for two and a half: two sizes are kept, the others are
  // compared, not kept, and the cache stays within its bytes.
  ShapeCache probe(kRoom);
  ASSERT_TRUE(probe.lookup(one).remembered);
  const std::uint64_t need = probe.bytes(), room = 2 * need + need / 2;
  ShapeCache small(room);
  std::size_t kept = 0;
  for (const float scale : {1.0f, 1.5f, 2.0f, 2.5f})
    kept += small.lookup(part(Mat4d{}, scale)).remembered ? 1 : 0;
  EXPECT_EQ(kept, 2u);
  EXPECT_LE(small.bytes(), room);
  EXPECT_TRUE(small.lookup(part(Mat4d::translation({0, 9, 0}), 1.0f)).placed);
  EXPECT_FALSE(small.lookup(part(Mat4d::translation({0, 9, 0}), 2.5f)).placed);
}

TEST(ShapeCache, APlacedMeshIsTheKeptOneMovedWithItsLevels) {
  const SourceObject object = part(Mat4d{});
  const PreparedObject prepared =
      prepareObject(object.positions, object.normals, object.colors, object.indices);
  const ProgressiveMesh mesh =
      buildProgressive(prepared.positions, prepared.indices, prepared.normals, prepared.colors, {});
  Random random(7);
  const Mat4d motion = test::randomMotion(random);
  const ProgressiveMesh placed = placedMesh(mesh, motion);
  ASSERT_EQ(placed.positions.size(), mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    EXPECT_LT(
        length(toDouble(placed.positions[v]) - motion.transformPoint(toDouble(mesh.positions[v]))),
        1e-4);
    EXPECT_LT(
        length(toDouble(placed.normals[v]) - motion.transformVector(toDouble(mesh.normals[v]))),
        1e-5);
  }
  EXPECT_EQ(placed.q, mesh.q);
  EXPECT_EQ(placed.triangles, mesh.triangles);
  EXPECT_EQ(placed.ecol, mesh.ecol);
  EXPECT_EQ(placed.map, mesh.map);
  EXPECT_EQ(placed.error, mesh.error);
  EXPECT_EQ(placed.colors, mesh.colors);
}

}  // namespace
}  // namespace lodforge
