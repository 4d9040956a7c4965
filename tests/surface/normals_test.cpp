#include "lodforge/surface/normals.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "lodforge/core/random.h"
#include "lodforge/surface/point_index.h"

namespace lodforge {
namespace {

constexpr double kDegree = std::numbers::pi / 180;

// The angle between two directions, in degrees.
double degreesBetween(Vec3d a, Vec3d b) {
  const double c = dot(a, b) / (length(a) * length(b));
  return std::acos(std::clamp(c, -1.0, 1.0)) / kDegree;
}

// `n` points spread at random over a 10 × 10 patch of the plane through `at` spanned by u and v.
std::vector<Vec3d> planeSamples(std::size_t n, Vec3d at, Vec3d u, Vec3d v, std::uint64_t seed) {
  Random random(seed);
  std::vector<Vec3d> points;
  for (std::size_t i = 0; i < n; ++i)
    points.push_back(at + u * random.uniform(-5, 5) + v * random.uniform(-5, 5));
  return points;
}

// `n` points spread uniformly over the sphere of `radius` round `centre`.
std::vector<Vec3d> sphereSamples(std::size_t n, Vec3d centre, double radius, std::uint64_t seed) {
  Random random(seed);
  std::vector<Vec3d> points;
  for (std::size_t i = 0; i < n; ++i) {
    const double z = random.uniform(-1, 1), phi = random.uniform(0, 2 * std::numbers::pi);
    const double r = std::sqrt(1 - z * z);
    points.push_back(centre + Vec3d{r * std::cos(phi), r * std::sin(phi), z} * radius);
  }
  return points;
}

// Every normal of points on a plane is the plane's, unit length, turned up with kUp; for any
// tilt of the plane (fixed seeds).
TEST(EstimateNormals, PointsOnAPlaneGetThePlanesNormalTurnedUp) {
  Random tilts(7);
  for (int trial = 0; trial < 8; ++trial) {
    const Vec3d axis = normalizeOr(
        Vec3d{tilts.uniform(-1, 1), tilts.uniform(-1, 1), tilts.uniform(0.2, 1)}, Vec3d{0, 0, 1});
    const Vec3d u = normalizeOr(cross(axis, Vec3d{0.3, -0.7, 0.1}), Vec3d{1, 0, 0});
    const Vec3d v = cross(axis, u);
    const std::vector<Vec3d> points =
        planeSamples(2'000, {100, -50, 20}, u, v, static_cast<std::uint64_t>(trial) + 1);
    const PointIndex index(points);
    NormalOptions up;
    up.orientation = NormalOrientation::kUp;
    const std::vector<Vec3f> normals = estimateNormals(points, index, up);
    ASSERT_EQ(normals.size(), points.size());
    for (std::size_t i = 0; i < normals.size(); ++i) {
      ASSERT_NEAR(length(normals[i]), 1.0f, 1e-5f) << trial << ' ' << i;
      ASSERT_GE(normals[i].z, 0.0f) << trial << ' ' << i;
      ASSERT_LT(degreesBetween(toDouble(normals[i]), axis), 0.1) << trial << ' ' << i;
    }
  }
}

// Propagation turns a closed object's normals all outwards: on a sphere each is radial, out.
TEST(EstimateNormals, PropagationTurnsASpheresNormalsOutwards) {
  const Vec3d centre{3, -2, 10};
  const std::vector<Vec3d> points = sphereSamples(5'000, centre, 2.5, 11);
  const PointIndex index(points);
  const std::vector<Vec3f> normals = estimateNormals(points, index, {});
  ASSERT_EQ(normals.size(), points.size());
  double worst = 0;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    ASSERT_NEAR(length(normals[i]), 1.0f, 1e-5f) << i;
    worst = std::max(worst, degreesBetween(toDouble(normals[i]), points[i] - centre));
  }
  // Twelve neighbours span about 6 degrees of the sphere: their plane is within a few degrees of
  // the tangent (4.0 at worst with this seed).
  EXPECT_LT(worst, 5.0);
}

// Towards a viewpoint: every normal faces it, whichever side of the plane it is on.
TEST(EstimateNormals, ViewpointTurnsEveryNormalTowardsIt) {
  const std::vector<Vec3d> points = planeSamples(1'000, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 3);
  const PointIndex index(points);
  for (const double side : {-1.0, 1.0}) {
    const Vec3d viewpoint{2, -1, 30 * side};
    const std::vector<Vec3f> normals = estimateNormals(
        points, index, {.orientation = NormalOrientation::kViewpoint, .viewpoint = viewpoint});
    for (std::size_t i = 0; i < normals.size(); ++i) {
      ASSERT_GT(dot(toDouble(normals[i]), viewpoint - points[i]), 0) << side << ' ' << i;
      ASSERT_LT(degreesBetween(toDouble(normals[i]), Vec3d{0, 0, side}), 0.1) << side << ' ' << i;
    }
  }
}

// The normals do not depend on the thread count (the queries run in parallel, the propagation
// does not).
TEST(EstimateNormals, TheSameForAnyThreadCount) {
  std::vector<Vec3d> points = sphereSamples(3'000, {0, 0, 0}, 1, 5);
  Random noise(6);
  for (Vec3d& p : points) p = p * (1 + noise.uniform(-0.01, 0.01));
  const PointIndex index(points);
  tbb::task_arena one(1), four(4);
  const std::vector<Vec3f> a = one.execute([&] { return estimateNormals(points, index, {}); });
  const std::vector<Vec3f> b = four.execute([&] { return estimateNormals(points, index, {}); });
  EXPECT_EQ(a, b);
}

// Fewer than three points have no plane: each gets +z.
TEST(EstimateNormals, FewerThanThreePointsFaceUp) {
  const std::vector<Vec3d> points = {{0, 0, 0}, {1, 2, 3}};
  const PointIndex index(points);
  EXPECT_EQ(estimateNormals(points, index, {}), (std::vector<Vec3f>(2, Vec3f{0, 0, 1})));
}

// On a regular grid the nearest neighbour is one step away everywhere; a single point or a
// point repeated has no spacing.
TEST(MedianSpacing, IsTheStepOfARegularGridAndZeroWithoutTwoDistinctPoints) {
  std::vector<Vec3d> grid;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 40; ++i) grid.push_back({1000 + 0.25 * i, -20 + 0.25 * j, 5});
  const PointIndex index(grid);
  EXPECT_DOUBLE_EQ(medianSpacing(grid, index), 0.25);
  EXPECT_DOUBLE_EQ(medianSpacing(grid, index, 10), 0.25);
  const std::vector<Vec3d> one = {{1, 2, 3}}, same(5, Vec3d{1, 2, 3});
  EXPECT_EQ(medianSpacing(one, PointIndex(one)), 0);
  EXPECT_EQ(medianSpacing(same, PointIndex(same)), 0);
}

}  // namespace
}  // namespace lodforge
