#include "lodforge/core/mesh.h"

#include <algorithm>
#include <numeric>
#include <queue>
#include <vector>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"

namespace lodforge {
namespace {

// An n x n grid of unit squares as a triangle soup (every triangle has its own 3 vertices).
void gridSoup(int n, std::vector<Vec3f>& positions, std::vector<std::uint32_t>& indices,
              float z = 0) {
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Vec3f a{float(i), float(j), z}, b{float(i + 1), float(j), z},
          c{float(i + 1), float(j + 1), z}, d{float(i), float(j + 1), z};
      for (Vec3f p : {a, b, c, a, c, d}) {
        indices.push_back(static_cast<std::uint32_t>(positions.size()));
        positions.push_back(p);
      }
    }
  }
}

// A flat-shaded cube: 24 vertices (4 per face, each with the face normal), 12 triangles.
void flatCube(std::vector<Vec3f>& positions, std::vector<Vec3f>& normals,
              std::vector<std::uint32_t>& indices) {
  const Vec3f axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < 3; ++a) {
    for (float sign : {1.0f, -1.0f}) {
      const Vec3f n = axes[a] * sign, u = axes[(a + 1) % 3], v = cross(n, u);
      const auto base = static_cast<std::uint32_t>(positions.size());
      for (auto [s, t] : {std::pair{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}}) {
        positions.push_back(n + u * s + v * t);
        normals.push_back(n);
      }
      indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
  }
}

TEST(Bounds, MatchesMinimumAndMaximumOfRandomPoints) {
  Random random(7);
  std::vector<Vec3f> points(1000);
  for (Vec3f& p : points)
    p = {float(random.uniform(-5, 3)), float(random.uniform(2, 9)), float(random.uniform(-1, 1))};
  const Aabb box = computeBounds(points);
  for (int axis = 0; axis < 3; ++axis) {
    const auto [lo, hi] = std::minmax_element(points.begin(), points.end(),
                                              [&](Vec3f a, Vec3f b) { return a[axis] < b[axis]; });
    EXPECT_EQ(box.min[axis], (*lo)[axis]);
    EXPECT_EQ(box.max[axis], (*hi)[axis]);
  }
  EXPECT_TRUE(computeBounds({}).empty());
}

TEST(Weld, ExactWeldOfGridSoupLeavesOneVertexPerGridPoint) {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  gridSoup(10, positions, indices);
  std::vector<std::uint32_t> remap(positions.size());
  const std::uint32_t unique = weldVertices(positions, {}, {}, {}, remap);
  EXPECT_EQ(unique, 11u * 11u);
  // Every triangle corner keeps its exact position.
  std::vector<Vec3f> welded(unique);
  remapVertexAttribute<Vec3f>(positions, remap, welded);
  for (std::size_t v = 0; v < positions.size(); ++v) EXPECT_EQ(welded[remap[v]], positions[v]);
  // New indices are dense and numbered in order of first occurrence.
  std::uint32_t next = 0;
  for (std::uint32_t r : remap) {
    ASSERT_LE(r, next);
    if (r == next) ++next;
  }
}

TEST(Weld, NegativeZeroWeldsWithPositiveZero) {
  const std::vector<Vec3f> positions = {{0.0f, 1, 2}, {-0.0f, 1, 2}};
  std::vector<std::uint32_t> remap(2);
  EXPECT_EQ(weldVertices(positions, {}, {}, {}, remap), 1u);
}

TEST(Weld, EpsilonMergesNearbyPointsOnly) {
  Random random(3);
  std::vector<Vec3f> positions;
  // Clusters of points within 0.01 of a centre, centres at least 1 apart.
  for (int c = 0; c < 50; ++c) {
    const Vec3f centre{float(c % 5) * 2.0f, float(c / 5) * 2.0f, 0};
    for (int k = 0; k < 4; ++k) {
      positions.push_back(centre + Vec3f{float(random.uniform(-0.003, 0.003)),
                                         float(random.uniform(-0.003, 0.003)),
                                         float(random.uniform(-0.003, 0.003))});
    }
  }
  std::vector<std::uint32_t> remap(positions.size());
  WeldOptions options;
  options.epsilon = 0.02f;
  EXPECT_EQ(weldVertices(positions, {}, {}, options, remap), 50u);
  for (std::size_t v = 0; v < positions.size(); ++v) EXPECT_EQ(remap[v], v / 4);
  options.epsilon = 1e-6f;
  EXPECT_EQ(weldVertices(positions, {}, {}, options, remap), positions.size());
}

TEST(Weld, KeepsNormalSplitsOnlyWhenAsked) {
  std::vector<Vec3f> positions, normals;
  std::vector<std::uint32_t> indices;
  flatCube(positions, normals, indices);
  std::vector<std::uint32_t> remap(positions.size());
  EXPECT_EQ(weldVertices(positions, normals, {}, {}, remap), 8u);
  WeldOptions keep;
  keep.keepNormalSplits = true;
  EXPECT_EQ(weldVertices(positions, normals, {}, keep, remap), 24u);
  // A second copy of every vertex with a normal tilted by ~0.1 degree welds into the first.
  std::vector<Vec3f> doubled = positions, doubledNormals = normals;
  for (std::size_t v = 0; v < positions.size(); ++v) {
    doubled.push_back(positions[v]);
    doubledNormals.push_back(normalizeOr(normals[v] + Vec3f{0.001f, 0.001f, 0.001f}, Vec3f{}));
  }
  remap.resize(doubled.size());
  EXPECT_EQ(weldVertices(doubled, doubledNormals, {}, keep, remap), 24u);
  for (std::size_t v = 0; v < positions.size(); ++v)
    EXPECT_EQ(remap[v + positions.size()], remap[v]);
}

TEST(Weld, KeepsColorSplitsOnlyWhenAsked) {
  const std::vector<Vec3f> positions = {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
  const std::vector<Rgba8> colors = {{255, 0, 0, 255}, {0, 255, 0, 255}, {255, 0, 0, 255}};
  std::vector<std::uint32_t> remap(3);
  EXPECT_EQ(weldVertices(positions, {}, colors, {}, remap), 1u);
  WeldOptions keep;
  keep.keepColorSplits = true;
  EXPECT_EQ(weldVertices(positions, {}, colors, keep, remap), 2u);
  EXPECT_EQ(remap[2], remap[0]);
}

TEST(Degenerate, DropsRepeatedCornersAndZeroAreaTriangles) {
  const std::vector<Vec3f> positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
  std::vector<std::uint32_t> indices = {0, 1, 2,   // good
                                        0, 0, 2,   // repeated corner
                                        0, 1, 3,   // collinear: zero area
                                        2, 1, 0};  // good (reversed)
  std::vector<std::uint32_t> copy = indices;
  EXPECT_EQ(removeDegenerateTriangles(positions, indices), 2u);
  EXPECT_EQ(std::vector<std::uint32_t>(indices.begin(), indices.begin() + 6),
            (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 0}));
  EXPECT_EQ(removeDegenerateTriangles(positions, copy, {.zeroArea = false}), 3u);
}

TEST(Normals, PlaneGetsItsNormalAndClosedCubeGetsDiagonals) {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  gridSoup(3, positions, indices, 5.0f);
  std::vector<Vec3f> normals(positions.size());
  computeVertexNormals(positions, indices, normals);
  for (const Vec3f& n : normals) EXPECT_EQ(n, (Vec3f{0, 0, 1}));

  std::vector<Vec3f> cubePositions, cubeNormals;
  std::vector<std::uint32_t> cubeIndices;
  flatCube(cubePositions, cubeNormals, cubeIndices);
  std::vector<std::uint32_t> remap(cubePositions.size());
  const std::uint32_t unique = weldVertices(cubePositions, {}, {}, {}, remap);
  std::vector<Vec3f> corners(unique);
  remapVertexAttribute<Vec3f>(cubePositions, remap, corners);
  remapIndices(cubeIndices, remap);
  std::vector<Vec3f> smooth(unique);
  computeVertexNormals(corners, cubeIndices, smooth);
  for (std::uint32_t v = 0; v < unique; ++v) {
    // Each corner's normal points along its position (the cube's diagonal).
    EXPECT_NEAR(dot(smooth[v], normalizeOr(corners[v], Vec3f{})), 1.0f, 1e-5f);
  }
}

// Reference: breadth-first search over triangles sharing a vertex.
std::uint32_t componentsByBfs(std::uint32_t vertexCount,
                              const std::vector<std::uint32_t>& indices) {
  const std::size_t triangles = indices.size() / 3;
  std::vector<std::vector<std::uint32_t>> byVertex(vertexCount);
  for (std::uint32_t t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) byVertex[indices[3 * t + std::size_t(k)]].push_back(t);
  }
  std::vector<bool> seen(triangles, false);
  std::uint32_t count = 0;
  for (std::uint32_t start = 0; start < triangles; ++start) {
    if (seen[start]) continue;
    ++count;
    std::queue<std::uint32_t> queue;
    queue.push(start);
    seen[start] = true;
    while (!queue.empty()) {
      const std::uint32_t t = queue.front();
      queue.pop();
      for (int k = 0; k < 3; ++k) {
        for (std::uint32_t other : byVertex[indices[3 * t + std::size_t(k)]]) {
          if (!seen[other]) {
            seen[other] = true;
            queue.push(other);
          }
        }
      }
    }
  }
  return count;
}

TEST(Components, MatchBreadthFirstSearchOnRandomMeshes) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Random random(seed);
    const auto vertexCount = static_cast<std::uint32_t>(20 + random.below(200));
    std::vector<std::uint32_t> indices(3 * (5 + random.below(100)));
    for (std::uint32_t& i : indices) i = static_cast<std::uint32_t>(random.below(vertexCount));
    std::vector<std::uint32_t> labels(indices.size() / 3);
    const std::uint32_t count = connectedComponents(vertexCount, indices, labels);
    EXPECT_EQ(count, componentsByBfs(vertexCount, indices)) << "seed " << seed;
    // Labels are numbered in order of first appearance, and connected triangles share one.
    std::uint32_t next = 0;
    for (std::uint32_t label : labels) {
      ASSERT_LE(label, next);
      if (label == next) ++next;
    }
    EXPECT_EQ(next, count);
  }
}

TEST(Components, TwoSeparateGridsAreTwo) {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  gridSoup(4, positions, indices, 0);
  gridSoup(4, positions, indices, 3);
  std::vector<std::uint32_t> remap(positions.size());
  const std::uint32_t unique = weldVertices(positions, {}, {}, {}, remap);
  remapIndices(indices, remap);
  std::vector<std::uint32_t> labels(indices.size() / 3);
  EXPECT_EQ(connectedComponents(unique, indices, labels), 2u);
}

TEST(Referenced, DropsUnusedVertices) {
  const std::vector<std::uint32_t> indices = {4, 1, 3, 3, 1, 0};
  std::vector<std::uint32_t> remap(6);
  EXPECT_EQ(findReferencedVertices(6, indices, remap), 4u);
  EXPECT_EQ(remap, (std::vector<std::uint32_t>{0, 1, ~0u, 2, 3, ~0u}));
  const std::vector<int> values = {10, 11, 12, 13, 14, 15};
  std::vector<int> kept(4);
  compactVertexAttribute<int>(values, remap, kept);
  EXPECT_EQ(kept, (std::vector<int>{10, 11, 13, 14}));
}

TEST(Boundary, GridHasItsRimAndClosedCubeNone) {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  gridSoup(5, positions, indices);
  std::vector<std::uint32_t> remap(positions.size());
  weldVertices(positions, {}, {}, {}, remap);
  remapIndices(indices, remap);
  EXPECT_EQ(countBoundaryEdges(indices), 20u);

  std::vector<Vec3f> cube, normals;
  std::vector<std::uint32_t> cubeIndices;
  flatCube(cube, normals, cubeIndices);
  EXPECT_EQ(countBoundaryEdges(cubeIndices), 6u * 4u);  // unwelded: every face is open
  std::vector<std::uint32_t> cubeRemap(cube.size());
  weldVertices(cube, {}, {}, {}, cubeRemap);
  remapIndices(cubeIndices, cubeRemap);
  EXPECT_EQ(countBoundaryEdges(cubeIndices), 0u);
}

}  // namespace
}  // namespace lodforge
