#include "lodforge/tiling/simplify_node.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "lodforge/core/distance.h"

namespace lodforge {
namespace {

using Key = std::tuple<double, double, double>;
Key keyOf(Vec3d p) {
  return {p.x, p.y, p.z};
}

double heightAt(double x, double y) {
  return 0.3 * std::sin(x * 0.2) * std::cos(y * 0.25);
}

Rgba8 colorAt(Vec3d p) {
  return {static_cast<std::uint8_t>(p.x * 10), static_cast<std::uint8_t>(p.y * 10), 7, 255};
}

// The gentle surface z = heightAt(x, y) over leaf cell (cx, cy) of an 8-unit grid: two triangles
// a unit square, vertices at whole x and y, so neighbouring cells' pieces share bit-identical
// border vertices (as the chunk cuts make them). One object (feature 7), colours by position.
MeshPart cellPiece(int cx, int cy) {
  MeshPart mesh;
  for (int y = 0; y <= 8; ++y)
    for (int x = 0; x <= 8; ++x) {
      const double px = cx * 8 + x, py = cy * 8 + y;
      mesh.positions.push_back({px, py, heightAt(px, py)});
      mesh.colors.push_back(colorAt(mesh.positions.back()));
      mesh.features.push_back(7);
    }
  const auto at = [](int x, int y) { return static_cast<std::uint32_t>(y * 9 + x); };
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      mesh.indices.insert(mesh.indices.end(), {at(x, y), at(x + 1, y), at(x + 1, y + 1)});
      mesh.indices.insert(mesh.indices.end(), {at(x, y), at(x + 1, y + 1), at(x, y + 1)});
    }
  return mesh;
}

// The grid of 4 × 4 × 1 leaf cells of 8 units, and the level-1 node over cells (0..1, 0..1):
// its outer faces shared with other tiles are the planes x = 16 and y = 16 (x = 0, y = 0 and
// both z planes are the grid's own ends).
const ChunkGrid kGrid{{0, 0, -1}, 8, {4, 4, 1}};
bool onOuterFace(Vec3d p) {
  return p.x == 16 || p.y == 16;
}

struct Node {
  std::vector<MeshPart> children;
  OctreeNode node;
};

Node surfaceNode() {
  Node n;
  for (int cy = 0; cy < 2; ++cy)
    for (int cx = 0; cx < 2; ++cx) n.children.push_back(cellPiece(cx, cy));
  n.node.level = 1;
  n.node.cell = {0, 0, 0};
  for (const MeshPart& child : n.children) n.node.bounds.add(boundsOf(child));
  return n;
}

std::uint64_t trianglesOf(const std::vector<MeshPart>& parts) {
  std::uint64_t triangles = 0;
  for (const MeshPart& part : parts) triangles += part.triangleCount();
  return triangles;
}

double distanceToMesh(Vec3d p, const MeshPart& mesh) {
  double best = std::numeric_limits<double>::max();
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
    best = std::min(best, pointTriangleDistanceSquared(p, mesh.positions[mesh.indices[t]],
                                                       mesh.positions[mesh.indices[t + 1]],
                                                       mesh.positions[mesh.indices[t + 2]]));
  return std::sqrt(best);
}

// The parent keeps every vertex on its outer faces, bit for bit (a neighbouring tile meets them),
// reaches the reduction's target, and welds the children: no seam is left open inside it, and
// the seams inside may simplify. Colours and features stay with their vertices.
TEST(SimplifyNode, KeepsItsOuterFacesBitIdenticalAndReachesItsTarget) {
  Node n = surfaceNode();
  std::set<Key> outer, seam;
  for (const MeshPart& child : n.children)
    for (const Vec3d& p : child.positions) {
      if (onOuterFace(p)) outer.insert(keyOf(p));
      if (!onOuterFace(p) && (p.x == 8 || p.y == 8)) seam.insert(keyOf(p));
    }
  ASSERT_EQ(outer.size(), 33u);
  const std::uint64_t target = static_cast<std::uint64_t>(0.2 * trianglesOf(n.children));
  const SimplifiedNode out = simplifyNode(std::move(n.children), kGrid, n.node, {});
  const MeshPart& mesh = out.mesh;
  EXPECT_LE(mesh.triangleCount(), target);
  EXPECT_GE(mesh.triangleCount(), target - 2);
  ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
  ASSERT_EQ(mesh.features.size(), mesh.positions.size());
  std::set<Key> kept;
  std::size_t seamKept = 0;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3d& p = mesh.positions[v];
    EXPECT_TRUE(kept.insert(keyOf(p)).second) << "not welded: " << p.x << ' ' << p.y;
    EXPECT_EQ(p.z, heightAt(p.x, p.y)) << "moved: " << p.x << ' ' << p.y;
    EXPECT_EQ(mesh.colors[v], colorAt(p));
    EXPECT_EQ(mesh.features[v], 7u);
    seamKept += seam.count(keyOf(p));
  }
  for (const Key& k : outer) {
    EXPECT_EQ(kept.count(k), 1u) << std::get<0>(k) << ' ' << std::get<1>(k);
  }
  EXPECT_GE(out.lockedVertices, outer.size());
  EXPECT_LT(seamKept, seam.size() / 2);
  // Every edge used once lies on the surface's rim: the children met along their seams.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = mesh.indices[t + k], b = mesh.indices[t + (k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  const auto onRim = [](Vec3d p) { return p.x == 0 || p.y == 0 || p.x == 16 || p.y == 16; };
  for (const auto& [edge, count] : uses)
    if (count == 1) {
      EXPECT_TRUE(onRim(mesh.positions[edge.first]) && onRim(mesh.positions[edge.second]));
    }
  EXPECT_EQ(out.droppedSegments, 0u);
  EXPECT_EQ(out.droppedError, 0);
}

// Each child its own texture chart (a quadrant of the texture): the children's shared borders are
// UV seams, two vertices at each point. The parent slides them with both sides together: fewer
// seam points remain, none moved off the surface or its coordinates, no crack opens along a seam
// (every edge used once is on the rim), and every triangle's corners come from one chart.
TEST(SimplifyNode, TexturedSeamsSlideWithBothSidesAndEveryTriangleKeepsOneChart) {
  Node n = surfaceNode();
  const auto uvOf = [](int chart, Vec3d p) {
    const int cx = chart % 2, cy = chart / 2;
    return Vec2f{float((p.x - 8 * cx) / 8 * 0.45 + 0.5 * cx),
                 float((p.y - 8 * cy) / 8 * 0.45 + 0.5 * cy)};
  };
  const auto chartOf = [](Vec2f uv) { return int(uv.x * 2) + 2 * int(uv.y * 2); };
  std::set<Key> seam;
  for (int c = 0; c < 4; ++c) {
    MeshPart& child = n.children[static_cast<std::size_t>(c)];
    for (const Vec3d& p : child.positions) {
      child.uvs.push_back(uvOf(c, p));
      child.materials.push_back(0);
      if (!onOuterFace(p) && (p.x == 8 || p.y == 8)) seam.insert(keyOf(p));
    }
  }
  const std::uint64_t target = static_cast<std::uint64_t>(0.2 * trianglesOf(n.children));
  const SimplifiedNode out = simplifyNode(std::move(n.children), kGrid, n.node, {});
  const MeshPart& mesh = out.mesh;
  EXPECT_LE(mesh.triangleCount(), target);
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  std::map<Key, std::uint32_t> point;  // one number per position
  std::set<Key> seamKept;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3d& p = mesh.positions[v];
    EXPECT_EQ(p.z, heightAt(p.x, p.y)) << "moved: " << p.x << ' ' << p.y;
    EXPECT_EQ(mesh.uvs[v], uvOf(chartOf(mesh.uvs[v]), p)) << p.x << ' ' << p.y;
    point.emplace(keyOf(p), static_cast<std::uint32_t>(point.size()));
    if (seam.count(keyOf(p)) != 0) seamKept.insert(keyOf(p));
  }
  EXPECT_LT(seamKept.size(), seam.size() / 2);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const int chart = chartOf(mesh.uvs[mesh.indices[t]]);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(chartOf(mesh.uvs[mesh.indices[t + k]]), chart) << "triangle " << t / 3;
      const std::uint32_t a = point[keyOf(mesh.positions[mesh.indices[t + k]])];
      const std::uint32_t b = point[keyOf(mesh.positions[mesh.indices[t + (k + 1) % 3]])];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::vector<Vec3d> at(point.size());
  for (const auto& [key, i] : point) at[i] = {std::get<0>(key), std::get<1>(key), std::get<2>(key)};
  const auto onRim = [](Vec3d p) { return p.x == 0 || p.y == 0 || p.x == 16 || p.y == 16; };
  for (const auto& [edge, count] : uses) {
    EXPECT_TRUE(count == 2 || (count == 1 && onRim(at[edge.first]) && onRim(at[edge.second])))
        << at[edge.first].x << ' ' << at[edge.first].y << " used " << count;
  }
}

// The simplification error bounds how far every vertex of the children is from the parent's
// surface, however few area samples measure it (removed vertices are bounded on their own: the
// samples could miss them); and it is reproducible.
TEST(SimplifyNode, ItsErrorBoundsEveryChildVertexAndIsReproducible) {
  for (const std::uint32_t samples : {4u, 10'000u}) {
    Node n = surfaceNode();
    std::vector<Vec3d> input;
    for (const MeshPart& child : n.children)
      input.insert(input.end(), child.positions.begin(), child.positions.end());
    OctreeOptions options;
    options.errorSamples = samples;
    const SimplifiedNode out = simplifyNode(n.children, kGrid, n.node, options);
    ASSERT_GT(out.simplificationError, 0) << samples;
    ASSERT_TRUE(std::isfinite(out.simplificationError)) << samples;
    double worst = 0;
    for (const Vec3d& p : input) worst = std::max(worst, distanceToMesh(p, out.mesh));
    EXPECT_GT(worst, 0) << samples;
    EXPECT_LE(worst, out.simplificationError * (1 + 1e-6) + 1e-9) << samples;
    const SimplifiedNode again = simplifyNode(std::move(n.children), kGrid, n.node, options);
    EXPECT_EQ(again.mesh.positions, out.mesh.positions) << samples;
    EXPECT_EQ(again.mesh.indices, out.mesh.indices) << samples;
    EXPECT_EQ(again.simplificationError, out.simplificationError) << samples;
  }
}

// An island that collapses away entirely (a lone small triangle floating 2 units above the
// surface) leaves its vertices no fan to be measured against, and too little area for samples to
// find: the error still covers how far they are from what remains.
TEST(SimplifyNode, ItsErrorCoversAnIslandThatCollapsedAway) {
  Node n = surfaceNode();
  MeshPart island;
  for (const Vec3d p : {Vec3d{4.3, 4.3, 2}, Vec3d{4.31, 4.3, 2}, Vec3d{4.3, 4.31, 2}}) {
    island.positions.push_back(p);
    island.colors.push_back(colorAt(p));
    island.features.push_back(8);
  }
  island.indices = {0, 1, 2};
  n.children.push_back(island);
  n.node.bounds.add(boundsOf(island));
  OctreeOptions options;
  options.errorSamples = 4;
  const SimplifiedNode out = simplifyNode(n.children, kGrid, n.node, options);
  ASSERT_EQ(out.droppedSegments, 0u);
  for (const Vec3d& p : out.mesh.positions) ASSERT_LT(p.z, 1) << "the island was kept";
  double farthest = 0;
  for (const Vec3d& p : island.positions)
    farthest = std::max(farthest, distanceToMesh(p, out.mesh));
  EXPECT_GT(farthest, 1.5);
  EXPECT_LE(farthest, out.simplificationError * (1 + 1e-6));
}

// Small closed parts that cannot simplify and keep the parent over its target are left out,
// smallest first, only as many as the target asks; the surface on the outer faces never; the
// dropped error bounds how far every dropped point is from what remains.
TEST(SimplifyNode, LeavesOutTheSmallestSegmentsWhileOverItsTarget) {
  Node n = surfaceNode();
  constexpr int kParts = 200;
  const auto sizeOf = [](int i) { return 0.05 + 0.001 * i; };
  const auto cornerOf = [](int i) { return Vec3d{2 + 0.7 * (i % 20), 2 + 1.2 * (i / 20), 2}; };
  for (int i = 0; i < kParts; ++i) {
    // A tetrahedron: closed, four triangles no collapse can take.
    MeshPart& into = n.children[static_cast<std::size_t>(i % 4)];
    const auto first = static_cast<std::uint32_t>(into.positions.size());
    const Vec3d p = cornerOf(i);
    const double s = sizeOf(i);
    for (const Vec3d& q : {p, p + Vec3d{s, 0, 0}, p + Vec3d{0, s, 0}, p + Vec3d{0, 0, s}}) {
      into.positions.push_back(q);
      into.colors.push_back(colorAt(q));
      into.features.push_back(7);
    }
    for (const std::uint32_t c : {0u, 2u, 1u, 0u, 1u, 3u, 0u, 3u, 2u, 1u, 2u, 3u})
      into.indices.push_back(first + c);
  }
  const std::uint64_t target = static_cast<std::uint64_t>(0.2 * trianglesOf(n.children));
  const SimplifiedNode out = simplifyNode(n.children, kGrid, n.node, {});
  const MeshPart& mesh = out.mesh;
  EXPECT_LE(mesh.triangleCount(), target);
  std::set<Key> kept;
  for (const Vec3d& p : mesh.positions) kept.insert(keyOf(p));
  int keptParts = 0, smallestKept = kParts;
  std::vector<int> dropped;
  for (int i = 0; i < kParts; ++i) {
    if (kept.count(keyOf(cornerOf(i)))) {
      ++keptParts;
      smallestKept = std::min(smallestKept, i);
    } else {
      dropped.push_back(i);
    }
  }
  EXPECT_EQ(out.droppedSegments, dropped.size());
  ASSERT_GT(dropped.size(), 0u);
  EXPECT_GT(keptParts, 0);
  // Smallest first: every dropped part is smaller than every kept one.
  EXPECT_LT(dropped.back(), smallestKept);
  // Only as many as the target asks: one part more would have been under it.
  EXPECT_GT(mesh.triangleCount() + 4, target);
  for (const Vec3d& p : n.children[0].positions) {
    if (onOuterFace(p)) {
      EXPECT_EQ(kept.count(keyOf(p)), 1u);
    }
  }
  double worst = 0;
  for (int i : dropped) {
    const Vec3d p = cornerOf(i);
    const double s = sizeOf(i);
    for (const Vec3d& q : {p, p + Vec3d{s, 0, 0}, p + Vec3d{0, s, 0}, p + Vec3d{0, 0, s}})
      worst = std::max(worst, distanceToMesh(q, mesh));
  }
  EXPECT_GT(worst, 1);
  EXPECT_LE(worst, out.droppedError);
}

}  // namespace
}  // namespace lodforge
