#include "lodforge/generate/shapes.h"

#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"

namespace lodforge {
namespace {

// Signed volume of a closed mesh (positive when triangles face outwards).
double signedVolume(const PartMesh& mesh) {
  double volume = 0;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const Vec3d a = toDouble(mesh.positions[mesh.indices[t]]),
                b = toDouble(mesh.positions[mesh.indices[t + 1]]),
                c = toDouble(mesh.positions[mesh.indices[t + 2]]);
    volume += dot(a, cross(b, c)) / 6.0;
  }
  return volume;
}

// Boundary edges after welding positions (CAD splits vertices along creases; the surface is
// still closed).
std::uint64_t weldedBoundaryEdges(const PartMesh& mesh) {
  std::vector<std::uint32_t> remap(mesh.positions.size());
  weldVertices(mesh.positions, {}, {}, {}, remap);
  std::vector<std::uint32_t> indices = mesh.indices;
  remapIndices(indices, remap);
  return countBoundaryEdges(indices);
}

// Every vertex normal agrees with the faces that use it (no inverted patches).
void expectNormalsAgreeWithWinding(const PartMesh& mesh) {
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const Vec3f a = mesh.positions[mesh.indices[t]], b = mesh.positions[mesh.indices[t + 1]],
                c = mesh.positions[mesh.indices[t + 2]];
    const Vec3f n = cross(b - a, c - a);
    for (int k = 0; k < 3; ++k)
      ASSERT_GT(dot(n, mesh.normals[mesh.indices[t + std::size_t(k)]]), 0.0f) << t;
  }
}

TEST(Shapes, BoxIsClosedOutwardAndHasItsVolume) {
  for (int n : {1, 3}) {
    PartMesh mesh;
    addBox(mesh, {2, 3, 4}, n);
    EXPECT_EQ(mesh.indices.size() / 3, std::size_t(12 * n * n));
    EXPECT_NEAR(signedVolume(mesh), 24.0, 1e-4);
    EXPECT_EQ(weldedBoundaryEdges(mesh), 0u);
    expectNormalsAgreeWithWinding(mesh);
  }
}

TEST(Shapes, TubeIsClosedAndHoldsTheAnnulusVolume) {
  PartMesh mesh;
  const int segments = 64;
  addCylinderSide(mesh, 1.0f, 0, 2, segments, 3, true);
  addCylinderSide(mesh, 0.5f, 0, 2, segments, 3, false);
  addAnnulus(mesh, 0.5f, 1.0f, 0, segments, false);
  addAnnulus(mesh, 0.5f, 1.0f, 2, segments, true);
  EXPECT_EQ(weldedBoundaryEdges(mesh), 0u);
  const double polygonArea =
      0.5 * segments * std::sin(2 * 3.141592653589793 / segments);  // unit polygon
  EXPECT_NEAR(signedVolume(mesh), 2.0 * polygonArea * (1.0 - 0.25), 1e-4);
  expectNormalsAgreeWithWinding(mesh);
}

TEST(Shapes, RodWithCapsIsClosed) {
  PartMesh mesh;
  addCylinderSide(mesh, 0.1f, 0, 5, 12, 10, true);
  addDisk(mesh, 0.1f, 0, 12, false);
  addDisk(mesh, 0.1f, 5, 12, true);
  EXPECT_EQ(weldedBoundaryEdges(mesh), 0u);
  EXPECT_GT(signedVolume(mesh), 0.0);
  expectNormalsAgreeWithWinding(mesh);
}

TEST(Shapes, EarClippingTriangulatesConcaveProfiles) {
  const std::vector<Vec2f> lProfile = {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::vector<std::uint32_t> triangles;
  ASSERT_TRUE(triangulatePolygon(lProfile, triangles));
  ASSERT_EQ(triangles.size(), 3u * 4u);
  double area = 0;
  for (std::size_t t = 0; t < triangles.size(); t += 3) {
    const Vec2f a = lProfile[triangles[t]], b = lProfile[triangles[t + 1]],
                c = lProfile[triangles[t + 2]];
    const double twice = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    EXPECT_GT(twice, 0.0);  // counter-clockwise like the polygon
    area += twice / 2;
  }
  EXPECT_DOUBLE_EQ(area, 4.0);
}

TEST(Shapes, ExtrudedIBeamIsClosedWithProfileAreaTimesLength) {
  const float w = 1, h = 2, t = 0.25f, web = 0.125f;
  const std::vector<Vec2f> profile = {{-w, -h},     {w, -h},       {w, -h + t},    {web, -h + t},
                                      {web, h - t}, {w, h - t},    {w, h},         {-w, h},
                                      {-w, h - t},  {-web, h - t}, {-web, -h + t}, {-w, -h + t}};
  PartMesh mesh;
  addExtrusion(mesh, profile, 10, 7);
  EXPECT_EQ(weldedBoundaryEdges(mesh), 0u);
  const double area = 2 * (2 * w * t) + (2 * web) * (2 * h - 2 * t);
  EXPECT_NEAR(signedVolume(mesh), area * 10, 1e-3);
  expectNormalsAgreeWithWinding(mesh);
}

TEST(Shapes, PerforatedPlateSharesCellEdgesAndIsOpenAtRimAndHoles) {
  for (int segments : {8, 16, 32}) {
    PartMesh mesh;
    const int columns = 4, rows = 3;
    addPerforatedPlate(mesh, columns, rows, 1.0f, 0.3f, segments);
    EXPECT_EQ(mesh.indices.size() / 3, std::size_t(2 * segments * columns * rows));
    // Shared square points are welded: each cell contributes its hole ring plus its square
    // points, shared edges counted once.
    const int perSide = segments / 4;  // square points per side, one corner included
    const int squarePoints =
        (columns * perSide + 1) * (rows + 1) + (rows * perSide - rows) * (columns + 1);
    EXPECT_EQ(mesh.positions.size(), std::size_t(columns * rows * segments + squarePoints))
        << segments;
    // Open: the outer rim plus every hole rim, nothing else.
    const std::uint64_t rim = 2 * (columns + rows) * std::uint64_t(perSide);
    EXPECT_EQ(countBoundaryEdges(mesh.indices), rim + std::uint64_t(columns * rows * segments));
    for (const Vec3f& n : mesh.normals) EXPECT_EQ(n, (Vec3f{0, 0, 1}));
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
      const Vec3f a = mesh.positions[mesh.indices[t]], b = mesh.positions[mesh.indices[t + 1]],
                  c = mesh.positions[mesh.indices[t + 2]];
      ASSERT_GT(cross(b - a, c - a).z, 0.0f);
    }
  }
}

}  // namespace
}  // namespace lodforge
