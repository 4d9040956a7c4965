#include "lodforge/points/cluster.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"

namespace lodforge {
namespace {

// n points on the plane z = 0.5 x (tilted 26.6°), with a little noise.
std::vector<CloudPoint> tiltedPlane(std::size_t n, double noise, std::uint64_t seed) {
  Random random(seed);
  std::vector<CloudPoint> points(n);
  for (CloudPoint& p : points) {
    const double x = random.uniform(0, 10), y = random.uniform(0, 10);
    p.position = {x + 1000, y + 2000, 0.5 * x + random.uniform(-noise, noise)};
  }
  return points;
}

std::vector<CloudPoint> sphere(std::size_t n, double radius, std::uint64_t seed) {
  Random random(seed);
  std::vector<CloudPoint> points(n);
  for (CloudPoint& p : points) {
    Vec3d d;
    do {
      d = {random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
    } while (length(d) < 0.1 || length(d) > 1);
    p.position = normalizeOr(d, Vec3d{0, 0, 1}) * radius;
  }
  return points;
}

// Walks the tree: every node's points are the union of its children's, leaves are single points.
void checkTree(const std::vector<ClusterNode>& tree, std::size_t n) {
  ASSERT_EQ(tree.size(), 2 * n - 1);
  std::size_t leaves = 0;
  for (std::size_t i = 0; i < tree.size(); ++i) {
    const ClusterNode& node = tree[i];
    if (node.leaf()) {
      ++leaves;
      EXPECT_EQ(node.pointCount, 1u);
      EXPECT_EQ(node.error, 0);
      continue;
    }
    ASSERT_GT(node.firstChild, i);  // breadth-first: children after their parent
    ASSERT_LT(node.firstChild + 1, tree.size());
    const ClusterNode &a = tree[node.firstChild], &b = tree[node.firstChild + 1];
    EXPECT_EQ(a.pointCount + b.pointCount, node.pointCount);
    EXPECT_GE(node.error, std::max(a.error, b.error));  // monotone: cuts are cuts
    EXPECT_GE(node.radius, std::max(a.radius, b.radius) * 0.999f);
    EXPECT_NEAR(length(node.normal), 1.0f, 1e-4f);
  }
  EXPECT_EQ(leaves, n);
  EXPECT_EQ(tree[0].pointCount, n);
}

TEST(Cluster, BuildsABinaryTreeDownToSinglePoints) {
  std::vector<CloudPoint> points = tiltedPlane(3'000, 0.01, 1);
  const Vec3d origin{1005, 2005, 2.5};
  const std::vector<ClusterNode> tree = clusterBlock(points, origin, false);
  checkTree(tree, points.size());
  // The root's square: at the centroid, facing the plane's normal, covering every point.
  Vec3d centroid;
  for (const CloudPoint& p : points) centroid = centroid + p.position;
  centroid = centroid * (1.0 / 3'000);
  EXPECT_NEAR(length(toDouble(tree[0].position) + origin - centroid), 0, 1e-3);
  const Vec3d planeNormal = normalizeOr(Vec3d{-0.5, 0, 1}, Vec3d{});
  EXPECT_GT(dot(toDouble(tree[0].normal), planeNormal), 0.999);
  for (const CloudPoint& p : points) {
    const Vec3d d = p.position - centroid;
    const Vec3d inPlane = d - toDouble(tree[0].normal) * dot(d, toDouble(tree[0].normal));
    EXPECT_LE(length(inPlane), tree[0].radius * 1.0001 + 1e-4);
  }
  // A flat patch is fitted well: the error is the noise, far below the extent.
  EXPECT_LT(tree[0].error, 0.05);
}

TEST(Cluster, EstimatesNormalsByPcaOverTreeCellsFacingUp) {
  std::vector<CloudPoint> plane = tiltedPlane(2'000, 0, 2);
  clusterBlock(plane, {}, false);
  const Vec3f want = toFloat(normalizeOr(Vec3d{-0.5, 0, 1}, Vec3d{}));
  for (const CloudPoint& p : plane) EXPECT_GT(dot(p.normal, want), 0.9999f);
  // On a sphere the normals are radial (up to sign; they face +z).
  std::vector<CloudPoint> ball = sphere(4'000, 3, 3);
  clusterBlock(ball, {}, false);
  std::size_t good = 0;
  for (const CloudPoint& p : ball) {
    const Vec3f radial = toFloat(normalizeOr(p.position, Vec3d{}));
    good += std::abs(dot(p.normal, radial)) > 0.98f;
    EXPECT_GE(p.normal.z, 0);
  }
  EXPECT_GT(good, ball.size() * 97 / 100);
}

// The closed-form 3×3 eigen-solve (computeDirect) stays accurate at map coordinates (UTM
// metres, about 5e6) on a noisy survey plane, where rounding is largest.
TEST(Cluster, PcaNormalsHoldAtMapCoordinates) {
  std::vector<CloudPoint> plane = tiltedPlane(5'000, 0.001, 4);
  for (CloudPoint& p : plane) p.position = p.position + Vec3d{500'000, 5'000'000, 300};
  clusterBlock(plane, {500'005, 5'002'005, 302.5}, false);
  const Vec3f want = toFloat(normalizeOr(Vec3d{-0.5, 0, 1}, Vec3d{}));
  std::size_t good = 0;
  for (const CloudPoint& p : plane) good += dot(p.normal, want) > 0.99f;
  EXPECT_GT(good, plane.size() * 99 / 100);
}

// Leaves cover half the gap to their nearest neighbour (the clustering tree searched as a k-d
// tree), exactly as a brute-force search finds it, duplicates included.
TEST(Cluster, LeafRadiiAreHalfTheGapToTheNearestNeighbour) {
  for (std::uint64_t seed : {5, 6}) {
    std::vector<CloudPoint> points =
        seed == 5 ? tiltedPlane(3'000, 0.02, seed) : sphere(3'000, 4, seed);
    points[17].position = points[400].position;  // a duplicate
    std::vector<std::uint32_t> firstPoint;
    const std::vector<ClusterNode> tree = clusterBlock(points, {}, false, {}, &firstPoint);
    std::size_t leaves = 0, zero = 0;
    for (std::size_t i = 0; i < tree.size(); ++i) {
      if (!tree[i].leaf()) continue;
      ++leaves;
      const CloudPoint& p = points[firstPoint[i]];
      double nearest = std::numeric_limits<double>::infinity();
      for (const CloudPoint& q : points)
        if (&q != &p) nearest = std::min(nearest, length(q.position - p.position));
      EXPECT_NEAR(tree[i].radius, nearest / 2, 1e-6 * nearest) << "seed " << seed;
      zero += tree[i].radius == 0;
    }
    EXPECT_EQ(leaves, points.size());
    EXPECT_EQ(zero, 2u);
  }
}

// The same where the tree's separators come from median splits and points lie on them: a
// lattice (many points share each coordinate) with 40 copies of one point and pairs one float
// step apart.
TEST(Cluster, LeafRadiiAreExactOnLatticesAndManyDuplicates) {
  std::vector<CloudPoint> points;
  const auto add = [&](Vec3d position) {
    CloudPoint p;
    p.position = position;
    points.push_back(p);
  };
  for (int x = 0; x < 30; ++x)
    for (int y = 0; y < 30; ++y) add({double(x), double(y), 0.0});
  for (int k = 0; k < 40; ++k) add({7.0, 7.0, 0.0});
  for (int k = 0; k < 5; ++k) add({std::nextafter(3.0 + k, 100.0), 20.0, 0.0});
  std::vector<std::uint32_t> firstPoint;
  const std::vector<ClusterNode> tree = clusterBlock(points, {}, false, {}, &firstPoint);
  for (std::size_t i = 0; i < tree.size(); ++i) {
    if (!tree[i].leaf()) continue;
    const CloudPoint& p = points[firstPoint[i]];
    double nearest = std::numeric_limits<double>::infinity();
    for (const CloudPoint& q : points)
      if (&q != &p) nearest = std::min(nearest, length(q.position - p.position));
    ASSERT_EQ(static_cast<double>(tree[i].radius),
              static_cast<double>(static_cast<float>(nearest / 2)))
        << p.position.x << " " << p.position.y;
  }
}

TEST(Cluster, ErrorGrowsWithCurvatureAndNoise) {
  std::vector<CloudPoint> flat = tiltedPlane(2'000, 0, 4);
  std::vector<CloudPoint> noisy = tiltedPlane(2'000, 0.3, 4);
  std::vector<CloudPoint> ball = sphere(2'000, 5, 4);
  const float flatError = clusterBlock(flat, {}, false)[0].error;
  const float noisyError = clusterBlock(noisy, {}, false)[0].error;
  const float ballError = clusterBlock(ball, {}, false)[0].error;
  EXPECT_LT(flatError, 1e-3);
  EXPECT_GT(noisyError, 0.05);
  EXPECT_GT(ballError, 1.0);
  // The paper's E by hand for a two-point cluster: points at ±1 along x with normals tilted ±θ.
  std::vector<CloudPoint> two(2);
  const float t = 0.3f;
  two[0].position = {-1, 0, 0};
  two[0].normal = {-std::sin(t), 0, std::cos(t)};
  two[1].position = {1, 0, 0.2};
  two[1].normal = {std::sin(t), 0, std::cos(t)};
  ClusterOptions options;
  const std::vector<ClusterNode> tree = clusterBlock(two, {}, true, options);
  ASSERT_EQ(tree.size(), 3u);
  // Centroid (0, 0, 0.1), normal +z: each point 0.1 off the plane, each normal 1 − cos θ off.
  // Leaves have radius 0.5·|p0 − p1|; the root covers them: 1 + that (in its plane, x only).
  const double gap = std::sqrt(4 + 0.04) / 2;
  EXPECT_NEAR(tree[0].radius, 1 + gap, 1e-5);
  const double want = 0.5 * 0.1 + 0.5 * (1 + gap) * (1 - std::cos(t));
  EXPECT_NEAR(tree[0].error, want, 1e-5);
}

TEST(Cluster, CutsSplitTheTreeIntoThreeParts) {
  std::vector<CloudPoint> points = sphere(5'000, 2, 7);
  const std::vector<ClusterNode> tree = clusterBlock(points, {}, false);
  for (float tolerance : {0.0f, 0.001f, 0.01f, 0.1f, 1.0f, 100.0f}) {
    SCOPED_TRACE(tolerance);
    const LodCut cut = cutTree(tree, tolerance);
    EXPECT_EQ(cut.dropped + cut.resident.size() + cut.segment.size(), tree.size());
    // Part II covers every point exactly once.
    std::uint64_t covered = 0;
    for (const ClusterNode& n : cut.resident) {
      covered += n.pointCount;
      EXPECT_LE(n.error, tolerance == 0 ? 0 : tolerance);
    }
    EXPECT_EQ(covered, points.size());
    // Part III is breadth-first below Part II: walking the links finds every record once and
    // reaches every point as a leaf.
    std::vector<int> seen(cut.segment.size(), 0);
    std::vector<std::uint32_t> queue;
    for (const ClusterNode& n : cut.resident)
      if (!n.leaf()) queue.push_back(n.firstChild);
    std::uint64_t leaves = 0;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      for (std::uint32_t s = queue[q]; s < queue[q] + 2; ++s) {
        ASSERT_LT(s, cut.segment.size());
        ++seen[s];
        if (cut.segment[s].leaf()) {
          ++leaves;
        } else {
          ASSERT_GT(cut.segment[s].firstChild, s);
          queue.push_back(cut.segment[s].firstChild);
        }
      }
    }
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int k) { return k == 1; }));
    std::uint64_t residentLeaves = 0;
    for (const ClusterNode& n : cut.resident) residentLeaves += n.leaf();
    EXPECT_EQ(leaves + residentLeaves, points.size());
  }
  // A tolerance above the root's error keeps the root alone; zero keeps every point.
  EXPECT_EQ(cutTree(tree, 1e9f).resident.size(), 1u);
  EXPECT_EQ(cutTree(tree, 0).resident.size(), points.size());
}

TEST(Cluster, FindsTheToleranceForAResidentBudget) {
  std::vector<CloudPoint> points = sphere(4'000, 2, 9);
  const std::vector<ClusterNode> tree = clusterBlock(points, {}, false);
  for (std::size_t budget : {1u, 10u, 125u, 1000u, 4000u}) {
    const float tolerance = toleranceForResident(tree, budget);
    EXPECT_LE(cutTree(tree, tolerance).resident.size(), budget);
    // The smallest such: any error value below it keeps more.
    float below = -1;
    for (const ClusterNode& n : tree) {
      if (n.error < tolerance) below = std::max(below, n.error);
    }
    if (below >= 0) {
      EXPECT_GT(cutTree(tree, below).resident.size(), budget);
    }
  }
}

}  // namespace
}  // namespace lodforge
