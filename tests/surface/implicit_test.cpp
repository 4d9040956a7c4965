#include "lodforge/surface/implicit.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "lodforge/core/random.h"

namespace lodforge {
namespace {

struct Cloud {
  std::vector<Vec3d> positions;
  std::vector<Vec3f> normals;
  OrientedPoints view() const { return {positions, normals}; }
};

// Points on the plane z = 0.25 over [0, 4]², facing +z.
Cloud plane(std::size_t n, std::uint64_t seed) {
  Random random(seed);
  Cloud c;
  for (std::size_t i = 0; i < n; ++i) {
    c.positions.push_back({random.uniform(0, 4), random.uniform(0, 4), 0.25});
    c.normals.push_back({0, 0, 1});
  }
  return c;
}

// Near the plane the value is the signed distance to it; far from every point there is none.
TEST(SignedDistance, IsTheDistanceToAPlaneAndUnknownFarFromThePoints) {
  const Cloud cloud = plane(4000, 3);
  const VoxelGrid grid{{0, 0, -1}, 0.25, {17, 17, 17}};
  CornerValues values{{0, 0, 0}, {17, 17, 17}, {}};
  signedDistances(grid, cloud.view(), {}, values);
  int known = 0;
  for (std::uint32_t k = 0; k < 17; ++k) {
    const double z = -1 + 0.25 * k;
    for (std::uint32_t j = 2; j < 15; ++j)
      for (std::uint32_t i = 2; i < 15; ++i) {
        const float v = values.values[values.index(i, j, k)];
        if (std::abs(z - 0.25) < 0.3) {
          ASSERT_FALSE(std::isnan(v)) << i << ' ' << j << ' ' << k;
          EXPECT_NEAR(v, z - 0.25, 1e-6);
          ++known;
        }
        if (std::abs(z - 0.25) > 0.51) {
          EXPECT_TRUE(std::isnan(v)) << k;
        }
      }
  }
  EXPECT_GT(known, 300);
}

// A corner's value is the same bits in any box that holds it, given the points near it.
TEST(SignedDistance, ACornerHasTheSameValueInEveryBox) {
  Cloud cloud = plane(3000, 5);
  Random random(9);
  for (std::size_t i = 0; i < cloud.positions.size(); ++i) {
    cloud.positions[i].z += random.uniform(-0.05, 0.05);
    cloud.normals[i] =
        normalizeOr(Vec3f{static_cast<float>(random.uniform(-0.2, 0.2)), 0.1f, 1}, Vec3f{0, 0, 1});
  }
  const VoxelGrid grid{{0, 0, -1}, 0.2, {21, 21, 11}};
  CornerValues whole{{0, 0, 0}, {21, 21, 11}, {}};
  signedDistances(grid, cloud.view(), {}, whole);
  CornerValues part{{8, 5, 3}, {6, 7, 5}, {}};
  signedDistances(grid, cloud.view(), {}, part);
  std::uint32_t known = 0;
  for (std::uint32_t k = 0; k < 5; ++k)
    for (std::uint32_t j = 0; j < 7; ++j)
      for (std::uint32_t i = 0; i < 6; ++i) {
        const float a = part.values[part.index(i, j, k)];
        const float b = whole.values[whole.index(8 + i, 5 + j, 3 + k)];
        EXPECT_EQ(std::memcmp(&a, &b, 4), 0) << i << ' ' << j << ' ' << k;
        known += std::isfinite(a) ? 1 : 0;
      }
  // NaN has the same bits as NaN: the corners within the radius of the points (every layer but
  // the lowest, 0.65 below the plane) must have values, or the comparison proves nothing.
  EXPECT_EQ(known, 4u * 7 * 6);
}

// The cells spread by one thread or shared by rows between several hold the same bits.
TEST(SignedDistance, TheSameBitsForAnyThreadCount) {
  Cloud cloud = plane(3000, 7);
  Random random(4);
  for (Vec3d& p : cloud.positions) p.z += random.uniform(-0.05, 0.05);
  const VoxelGrid grid{{0, 0, -1}, 0.2, {21, 21, 11}};
  CornerSums sums(grid, {}, {2, 1, 0}, {17, 19, 11});
  for (std::size_t p = 0; p < cloud.positions.size(); ++p)
    sums.add(cloud.positions[p], cloud.normals[p]);
  tbb::task_arena one(1), three(3);
  const CornerValues a = one.execute([&] { return sums.values(); });
  const CornerValues b = three.execute([&] { return sums.values(); });
  const CornerValues c = sums.values(1), d = three.execute([&] { return sums.values(5); });
  ASSERT_EQ(a.values.size(), b.values.size());
  EXPECT_EQ(std::memcmp(a.values.data(), b.values.data(), a.values.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.values.data(), c.values.data(), a.values.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.values.data(), d.values.data(), a.values.size() * 4), 0);
  std::size_t known = 0;
  for (const float v : a.values) known += std::isnan(v) ? 0 : 1;
  EXPECT_GT(known, 500u);
}

#ifndef NDEBUG
// A caller's bug is an assert where asserts are on (the sanitizer builds): a point without a
// normal stops at the entry point instead of reading past the normals.
TEST(SignedDistanceDeathTest, AssertsThatEveryPointHasANormal) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  Cloud cloud = plane(100, 1);
  cloud.normals = std::vector<Vec3f>(50, Vec3f{0, 0, 1});
  const VoxelGrid grid{{0, 0, -1}, 0.25, {17, 17, 17}};
  CornerValues values{{0, 0, 0}, {17, 17, 17}, {}};
  EXPECT_DEATH(signedDistances(grid, cloud.view(), {}, values),
               "points.normals.size\\(\\) == points.positions.size\\(\\)");
}
#endif

}  // namespace
}  // namespace lodforge
