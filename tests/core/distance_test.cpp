#include "lodforge/core/distance.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"

namespace lodforge {
namespace {

// Nearest point of a triangle by brute force: a dense barycentric lattice plus the edges.
double bruteForceSquared(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  double best = std::numeric_limits<double>::max();
  const int n = 200;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const double u = double(i) / n, v = double(j) / n;
      const Vec3d q = a + (b - a) * u + (c - a) * v;
      best = std::min(best, dot(p - q, p - q));
    }
  }
  return best;
}

TEST(PointTriangleDistance, MatchesBruteForceInEveryRegion) {
  Random random(2);
  for (int i = 0; i < 300; ++i) {
    const Vec3d a{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
    const Vec3d b{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
    const Vec3d c{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
    const Vec3d p{random.uniform(-2, 2), random.uniform(-2, 2), random.uniform(-2, 2)};
    const double exact = pointTriangleDistanceSquared(p, a, b, c);
    const double brute = bruteForceSquared(p, a, b, c);
    EXPECT_LE(exact, brute + 1e-12);  // never farther than any point of the triangle
    EXPECT_NEAR(std::sqrt(exact), std::sqrt(brute), 0.02);
  }
  // Known answers: over the face, beyond an edge, beyond a corner.
  const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  EXPECT_DOUBLE_EQ(pointTriangleDistanceSquared({0.25, 0.25, 2}, a, b, c), 4.0);
  EXPECT_DOUBLE_EQ(pointTriangleDistanceSquared({0.5, -3, 0}, a, b, c), 9.0);
  EXPECT_DOUBLE_EQ(pointTriangleDistanceSquared({-3, -4, 0}, a, b, c), 25.0);
}

// A z = height grid over [0, size]^2, n x n squares.
void plane(int n, double size, double height, std::vector<Vec3f>& positions,
           std::vector<std::uint32_t>& indices) {
  positions.clear();
  indices.clear();
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      positions.push_back({float(size * x / n), float(size * y / n), float(height)});
  const auto at = [n](int x, int y) { return std::uint32_t(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      indices.insert(indices.end(), {at(x, y), at(x + 1, y), at(x + 1, y + 1)});
      indices.insert(indices.end(), {at(x, y), at(x + 1, y + 1), at(x, y + 1)});
    }
  }
}

TEST(SurfaceDistance, ParallelPlanesAreTheirOffsetApart) {
  std::vector<Vec3f> pa, pb;
  std::vector<std::uint32_t> ia, ib;
  plane(40, 10, 0, pa, ia);
  plane(7, 10, 0.25, pb, ib);  // coarser, lifted
  const SurfaceDistance d = surfaceDistance(pa, ia, pb, ib, 5000);
  EXPECT_NEAR(d.hausdorff, 0.25, 1e-6);
  EXPECT_NEAR(d.rms, 0.25, 1e-6);
  EXPECT_NEAR(d.meanAB, 0.25, 1e-6);
  const SurfaceDistance same = surfaceDistance(pa, ia, pa, ia, 5000);
  EXPECT_LT(same.hausdorff, 1e-9);
}

TEST(SurfaceDistance, GridSearchEqualsBruteForceOnEveryCorner) {
  // With no area samples, the samples are each triangle's first corner: the grid's answers can
  // be checked against a brute-force nearest over all triangles.
  Random random(9);
  std::vector<Vec3f> pa, pb;
  std::vector<std::uint32_t> ia, ib;
  plane(12, 4, 0, pa, ia);
  for (Vec3f& p : pa) p.z = float(random.uniform(-0.3, 0.3));  // rough
  plane(9, 4, 0, pb, ib);
  for (Vec3f& p : pb) p.z = float(0.5 * std::sin(p.x) * std::cos(p.y));
  for (Vec3f& p : pb) p.x += 0.7f;  // partly beside A: far points hit the grid's edges
  const SurfaceDistance d = surfaceDistance(pa, ia, pb, ib, 0, 1, /*corners=*/true);
  const auto nearest = [](Vec3f q, const std::vector<Vec3f>& p,
                          const std::vector<std::uint32_t>& i) {
    double best = std::numeric_limits<double>::max();
    for (std::size_t t = 0; t < i.size(); t += 3)
      best = std::min(
          best, pointTriangleDistanceSquared(toDouble(q), toDouble(p[i[t]]), toDouble(p[i[t + 1]]),
                                             toDouble(p[i[t + 2]])));
    return std::sqrt(best);
  };
  double maxAB = 0, sumAB = 0, maxBA = 0;
  for (std::size_t t = 0; t < ia.size(); t += 3) {
    const double e = nearest(pa[ia[t]], pb, ib);
    maxAB = std::max(maxAB, e);
    sumAB += e;
  }
  for (std::size_t t = 0; t < ib.size(); t += 3)
    maxBA = std::max(maxBA, nearest(pb[ib[t]], pa, ia));
  EXPECT_DOUBLE_EQ(d.hausdorff, std::max(maxAB, maxBA));
  EXPECT_NEAR(d.meanAB, sumAB / double(ia.size() / 3), 1e-12);
}

TEST(FarthestDistance, EqualsTheBruteForceFarthestOfRandomPoints) {
  // One-sided: the farthest of 500 random points (some far outside the surface's grid) from a
  // wavy surface, against a brute-force nearest over every triangle.
  Random random(13);
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  plane(10, 4, 0, positions, indices);
  for (Vec3f& p : positions) p.z = float(0.4 * std::sin(2 * p.x) * std::cos(p.y));
  std::vector<Vec3f> points(500);
  for (Vec3f& p : points)
    p = {float(random.uniform(-3, 7)), float(random.uniform(-3, 7)), float(random.uniform(-2, 2))};
  double want = 0;
  for (const Vec3f& p : points) {
    double best = std::numeric_limits<double>::max();
    for (std::size_t t = 0; t < indices.size(); t += 3)
      best =
          std::min(best, pointTriangleDistanceSquared(toDouble(p), toDouble(positions[indices[t]]),
                                                      toDouble(positions[indices[t + 1]]),
                                                      toDouble(positions[indices[t + 2]])));
    want = std::max(want, std::sqrt(best));
  }
  EXPECT_DOUBLE_EQ(farthestDistance(points, positions, indices), want);
  EXPECT_EQ(farthestDistance({}, positions, indices), 0);
  EXPECT_TRUE(std::isinf(farthestDistance(points, positions, {})));
}

TEST(NearestTriangles, VerticesNoTriangleUsesAndFarQueriesStayInTheGrid) {
  // The grid places every position, used or not: an unused vertex at 1e30 or NaN, and queries
  // 1e15 away from a triangle a millionth wide, are clamped to its edge cells (converted to an
  // int first, they overflowed: UBSan in the sanitizer run), and the distances stay exact.
  const std::vector<Vec3f> positions = {{0, 0, 0},
                                        {1e-6f, 0, 0},
                                        {0, 1e-6f, 0},
                                        {1e30f, 0, 0},
                                        {std::numeric_limits<float>::quiet_NaN(), 0, 0}};
  const std::vector<std::uint32_t> indices = {0, 1, 2};
  const NearestTriangles nearest(positions, indices);
  std::uint32_t triangle = ~0u;
  EXPECT_DOUBLE_EQ(nearest.nearestSquared({0, 0, 2}, triangle), 4.0);
  EXPECT_EQ(triangle, 0u);
  EXPECT_DOUBLE_EQ(nearest.nearestSquared({0, 0, -1e15}, triangle), 1e30);
  const std::vector<Vec3f> far = {{-1e15f, 0, 0}, {0, 0, 3}};
  EXPECT_DOUBLE_EQ(farthestDistance(far, positions, indices), -double(far[0].x));
}

TEST(NearestTriangles, FindsTheBruteForceNearestTriangleOfRandomPoints) {
  // A wavy surface and 500 random points in and far around it: the distance equals the
  // brute-force nearest over every triangle, and the triangle it names is at that distance.
  Random random(29);
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  plane(12, 5, 0, positions, indices);
  for (Vec3f& p : positions) p.z = float(0.3 * std::cos(3 * p.x) * std::sin(2 * p.y));
  const NearestTriangles nearest(positions, indices);
  const auto distanceTo = [&](Vec3d p, std::size_t t) {
    return pointTriangleDistanceSquared(p, toDouble(positions[indices[3 * t]]),
                                        toDouble(positions[indices[3 * t + 1]]),
                                        toDouble(positions[indices[3 * t + 2]]));
  };
  for (int i = 0; i < 500; ++i) {
    const Vec3d p{random.uniform(-4, 9), random.uniform(-4, 9), random.uniform(-3, 3)};
    double want = std::numeric_limits<double>::max();
    for (std::size_t t = 0; t < indices.size() / 3; ++t) want = std::min(want, distanceTo(p, t));
    std::uint32_t triangle = ~0u;
    EXPECT_DOUBLE_EQ(nearest.nearestSquared(p, triangle), want);
    ASSERT_LT(triangle, indices.size() / 3);
    EXPECT_DOUBLE_EQ(distanceTo(p, triangle), want);
  }
}

TEST(SampledHausdorff, EqualsTheFullMeasureOnRandomSurfaces) {
  // The early-ending searches must give exactly the maximum the full measure finds, on rough
  // surfaces partly beside each other, with and without corner samples.
  Random random(21);
  for (int round = 0; round < 12; ++round) {
    std::vector<Vec3f> pa, pb;
    std::vector<std::uint32_t> ia, ib;
    plane(5 + round, 4, 0, pa, ia);
    for (Vec3f& p : pa) p.z = float(random.uniform(-0.5, 0.5));
    plane(3 + 2 * round, 4, 0, pb, ib);
    const double shift = random.uniform(-1, 1);
    for (Vec3f& p : pb) {
      p.z = float(0.3 * std::sin(3 * p.x) + random.uniform(-0.1, 0.1));
      p.x += float(shift);
    }
    const bool corners = round % 2 == 0;
    const std::uint64_t seed = 100 + static_cast<std::uint64_t>(round);
    const SurfaceDistance full = surfaceDistance(pa, ia, pb, ib, 3000, seed, corners);
    EXPECT_DOUBLE_EQ(sampledHausdorff(pa, ia, pb, ib, 3000, seed, corners), full.hausdorff);
  }
  std::vector<Vec3f> pa;
  std::vector<std::uint32_t> ia;
  plane(3, 1, 0, pa, ia);
  EXPECT_TRUE(std::isinf(sampledHausdorff(pa, ia, pa, {}, 10)));
}

TEST(SurfaceDistance, CornerSamplesCatchASpikeThatAreaSamplesMiss) {
  std::vector<Vec3f> pa, pb;
  std::vector<std::uint32_t> ia, ib;
  plane(50, 10, 0, pa, ia);
  plane(1, 10, 0, pb, ib);
  pa[25 * 51 + 25].z = 3;  // one tall, thin spike
  const SurfaceDistance with = surfaceDistance(pa, ia, pb, ib, 200, 1, true);
  const SurfaceDistance without = surfaceDistance(pa, ia, pb, ib, 200, 1, false);
  EXPECT_NEAR(with.hausdorff, 3.0, 1e-6);
  EXPECT_LT(without.hausdorff, 3.0);
  // The largest distance is the spike's, from A, and it is where the spike's tip is.
  EXPECT_EQ(with.maxAB, with.hausdorff);
  EXPECT_LT(with.maxBA, 3.0);
  const Vec3d tip = toDouble(pa[25 * 51 + 25]);
  EXPECT_EQ(with.farthestOnA.x, tip.x);
  EXPECT_EQ(with.farthestOnA.y, tip.y);
  EXPECT_EQ(with.farthestOnA.z, tip.z);
  // Measured the other way round, the tip is B's farthest point.
  const SurfaceDistance swapped = surfaceDistance(pb, ib, pa, ia, 200, 1, true);
  EXPECT_NEAR(swapped.maxBA, 3.0, 1e-6);
  EXPECT_EQ(swapped.farthestOnB.z, tip.z);
  EXPECT_EQ(swapped.farthestOnB.x, tip.x);
}

}  // namespace
}  // namespace lodforge
