#include "lodforge/tiling/chunk_grid.h"

#include <cmath>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"
#include "lodforge/core/random.h"
#include "lodforge/io/model_io.h"
#include "lodforge/tiling/chunk_store.h"
#include "test_support.h"

namespace lodforge {
namespace {

double area(Vec3d a, Vec3d b, Vec3d c) {
  return 0.5 * length(cross(b - a, c - a));
}

TEST(ChunkGrid, CellsCoverTheBoundsAndClampTheFarFace) {
  Aabbd box;
  box.add(Vec3d{-1, 2, 3});
  box.add(Vec3d{9, 4.5, 3});  // flat in z
  const ChunkGrid grid = ChunkGrid::over(box, 2.5);
  EXPECT_EQ(grid.dims, (ChunkCell{4, 1, 1}));
  EXPECT_EQ(grid.cellOf({9, 4.5, 3}), (ChunkCell{3, 0, 0}));
  EXPECT_EQ(grid.cellOf({-1, 2, 3}), (ChunkCell{0, 0, 0}));
  EXPECT_EQ(grid.cellOf({1.5, 3, 3}), (ChunkCell{1, 0, 0}));
  EXPECT_DOUBLE_EQ(grid.plane(0, 2), 4.0);
}

TEST(ChunkGrid, DerivedSizeGivesAboutTheWantedTrianglesPerChunkOnASurface) {
  Aabbd box;
  box.add(Vec3d{0, 0, 0});
  box.add(Vec3d{1000, 500, 20});
  const double size = ChunkGrid::sizeFor(box, 10'000'000, 64 * 1024);
  const double chunks = (1000 / size) * (500 / size);
  EXPECT_NEAR(chunks, 10'000'000.0 / (64 * 1024), 1.0);
  EXPECT_DOUBLE_EQ(ChunkGrid::sizeFor(box, 1000, 64 * 1024), 1000.0);  // small: one chunk
}

TEST(CutTriangle, PiecesKeepTheAreaAndLieInTheirCells) {
  Random random(3);
  Aabbd box;
  box.add(Vec3d{0, 0, 0});
  box.add(Vec3d{10, 10, 10});
  const ChunkGrid grid = ChunkGrid::over(box, 1.7);
  std::vector<ChunkCell> cells;
  std::vector<CutCorner> corners;
  for (int i = 0; i < 2000; ++i) {
    std::array<CutCorner, 3> t;
    const double spread = i % 2 == 0 ? 10 : 2;  // big ones cross many planes
    const Vec3d base{random.uniform(0, 10 - spread), random.uniform(0, 10 - spread),
                     random.uniform(0, 10 - spread)};
    for (auto& c : t) {
      c.position = base + Vec3d{random.uniform(0, spread), random.uniform(0, spread),
                                random.uniform(0, spread)};
      c.color = {static_cast<std::uint8_t>(random.uniform(0, 255)), 10, 20, 255};
    }
    cells.clear();
    corners.clear();
    cutTriangle(grid, t, cells, corners);
    ASSERT_EQ(corners.size(), 3 * cells.size());
    double sum = 0;
    const Vec3d normal =
        normalizeOr(cross(t[1].position - t[0].position, t[2].position - t[0].position), Vec3d{});
    for (std::size_t p = 0; p < cells.size(); ++p) {
      const Vec3d a = corners[3 * p].position, b = corners[3 * p + 1].position,
                  c = corners[3 * p + 2].position;
      sum += area(a, b, c);
      // Same winding as the triangle it came from.
      EXPECT_GE(dot(cross(b - a, c - a), normal), -1e-12);
      const Aabbd cell = grid.cellBounds(cells[p]);
      for (std::size_t k = 0; k < 3; ++k) {
        const Vec3d q = corners[3 * p + k].position;
        for (int axis = 0; axis < 3; ++axis) {
          EXPECT_GE(q[axis], cell.min[axis] - 1e-12);
          EXPECT_LE(q[axis], cell.max[axis] + 1e-12);
        }
      }
    }
    EXPECT_NEAR(sum, area(t[0].position, t[1].position, t[2].position), 1e-9);
  }
}

TEST(CutTriangle, TrianglesInsideACellStayWholeAndDegenerateOnesVanish) {
  // Most of a mesh: a triangle within one cell (or touching its faces) is one piece, itself, in
  // the cell of its centroid; repeated corners or no area give nothing, inside a cell or across.
  Random random(11);
  Aabbd box;
  box.add(Vec3d{0, 0, 0});
  box.add(Vec3d{10, 10, 10});
  const ChunkGrid grid = ChunkGrid::over(box, 2.5);
  std::vector<ChunkCell> cells;
  std::vector<CutCorner> corners;
  for (int i = 0; i < 3000; ++i) {
    const ChunkCell cell{static_cast<std::int32_t>(random.uniform(0, 4)),
                         static_cast<std::int32_t>(random.uniform(0, 4)),
                         static_cast<std::int32_t>(random.uniform(0, 4))};
    const Aabbd bounds = grid.cellBounds(cell);
    std::array<CutCorner, 3> t;
    for (auto& c : t) {
      for (int axis = 0; axis < 3; ++axis) {
        // A third of the corners on a face of the cell.
        const double u =
            random.uniform(0, 3) < 1 ? std::round(random.uniform(0, 1)) : random.uniform(0, 1);
        c.position[axis] = bounds.min[axis] + u * (bounds.max[axis] - bounds.min[axis]);
      }
      c.normal = {0, 0, 1};
    }
    const int kind = i % 3;  // 0: a plain triangle, 1: a repeated corner, 2: collinear corners
    if (kind == 1) t[2].position = t[i % 2].position;
    if (kind == 2) t[2].position = t[0].position + (t[1].position - t[0].position) * 0.5;
    cells.clear();
    corners.clear();
    cutTriangle(grid, t, cells, corners);
    const bool flat =
        length(cross(t[1].position - t[0].position, t[2].position - t[0].position)) == 0;
    if (kind != 0 || flat) {
      if (kind == 1) {
        EXPECT_TRUE(cells.empty()) << i;
      }
      double sum = 0;
      for (std::size_t p = 0; p < cells.size(); ++p)
        sum +=
            area(corners[3 * p].position, corners[3 * p + 1].position, corners[3 * p + 2].position);
      EXPECT_NEAR(sum, 0, 1e-12) << i;
      continue;
    }
    ASSERT_EQ(cells.size(), 1u) << i;
    EXPECT_EQ(cells[0], grid.cellOf((t[0].position + t[1].position + t[2].position) / 3.0));
    for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(corners[k].position, t[k].position) << i;
  }
}

// A polygon piece of n corners becomes n − 2 triangles fanned from a corner, not n around its
// centroid: a triangle cut by one plane is 3 triangles (a triangle and a quad), not 5. Where a
// corner's fan would hold a flat triangle (two cuts on one edge leave corners in line) another
// corner is the apex; every piece still has area and no new corner appears.
TEST(CutTriangle, APolygonPieceIsFannedFromACornerIntoNMinusTwoTriangles) {
  Aabbd box;
  box.add(Vec3d{0, 0, 0});
  box.add(Vec3d{4, 4, 4});
  const ChunkGrid grid = ChunkGrid::over(box, 2);
  std::vector<ChunkCell> cells;
  std::vector<CutCorner> corners;
  std::array<CutCorner, 3> t;
  t[0].position = {0.5, 0.5, 1};
  t[1].position = {3.5, 0.5, 1};
  t[2].position = {0.5, 1.5, 1};
  cutTriangle(grid, t, cells, corners);  // the x = 2 plane cuts it: a quad and a triangle
  EXPECT_EQ(cells.size(), 3u);
  // Cut on both axes near a corner: pieces of up to 5 corners, two cuts on the long edge.
  t[0].position = {0.2, 0.2, 1};
  t[1].position = {3.8, 1.0, 1};
  t[2].position = {1.0, 3.8, 1};
  cells.clear();
  corners.clear();
  cutTriangle(grid, t, cells, corners);
  const std::set<std::tuple<double, double, double>> before = [&] {
    std::set<std::tuple<double, double, double>> seen;
    for (const CutCorner& c : corners) seen.emplace(c.position.x, c.position.y, c.position.z);
    return seen;
  }();
  double sum = 0;
  for (std::size_t p = 0; p < cells.size(); ++p) {
    const double a =
        area(corners[3 * p].position, corners[3 * p + 1].position, corners[3 * p + 2].position);
    EXPECT_GT(a, 0) << "piece " << p;
    sum += a;
  }
  EXPECT_NEAR(sum, area(t[0].position, t[1].position, t[2].position), 1e-12);
  // 4 pieces (one per cell it crosses) of 3 + 4 + 4 + 5 corners or so: far fewer triangles
  // than a centroid fan's one per corner, and no centroid among the corners.
  EXPECT_LE(cells.size(), 8u);
  for (const auto& [x, y, z] : before) {
    const bool onPlane = x == 2 || y == 2;
    const bool original = Vec3d{x, y, z} == t[0].position || Vec3d{x, y, z} == t[1].position ||
                          Vec3d{x, y, z} == t[2].position;
    EXPECT_TRUE(onPlane || original) << x << " " << y << " " << z << " is a new inner corner";
  }
}

TEST(CutTriangle, TrianglesSharingAnEdgeGetBitIdenticalCutVertices) {
  // A closed surface cut into chunks and welded exactly is still closed: every cut vertex on a
  // shared edge came out the same from both triangles, and no T-junction appeared.
  Result<Model> horse = readModel(test::dataPath("meshes/horse.ply"));
  ASSERT_TRUE(horse.ok()) << horse.error().message;
  MeshPart welded;
  for (const Vec3f& p : horse->positions) welded.positions.push_back(horse->origin + toDouble(p));
  welded.indices = horse->indices;
  weldExact(welded);
  ASSERT_EQ(countBoundaryEdges(welded.indices), 0u);  // the horse is closed
  Aabbd box;
  for (const Vec3d& p : welded.positions) box.add(p);
  for (double size : {box.longestSide() / 3.3, box.longestSide() / 7.1}) {
    const ChunkGrid grid = ChunkGrid::over(box, size);
    std::vector<ChunkCell> cells;
    std::vector<CutCorner> corners;
    for (std::size_t t = 0; t < welded.indices.size(); t += 3) {
      std::array<CutCorner, 3> triangle;
      for (std::size_t k = 0; k < 3; ++k)
        triangle[k] = {welded.positions[welded.indices[t + k]], {255, 255, 255, 255}, {0, 0, 1}};
      cutTriangle(grid, triangle, cells, corners);
    }
    EXPECT_GT(cells.size(), welded.indices.size() / 3);  // something was cut
    MeshPart pieces;
    for (std::size_t i = 0; i < corners.size(); ++i) {
      pieces.positions.push_back(corners[i].position);
      pieces.indices.push_back(static_cast<std::uint32_t>(i));
    }
    weldExact(pieces);
    EXPECT_EQ(countBoundaryEdges(pieces.indices), 0u) << "chunk size " << size;
  }
}

}  // namespace
}  // namespace lodforge
