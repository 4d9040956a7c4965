#include "lodforge/tiles/surface_input.h"

#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "test_support.h"

namespace lodforge {
namespace {

// A wavy open sheet, points uniform with their exact normals, as float (as the PLY holds them).
struct Cloud {
  std::vector<Vec3d> points;
  std::vector<Vec3f> normals;
};

Cloud sheet(std::size_t count, std::uint64_t seed) {
  Cloud c;
  Random random(seed);
  for (std::size_t i = 0; i < count; ++i) {
    const double x = random.uniform(0, 80), y = random.uniform(0, 50);
    c.points.push_back(toDouble(toFloat(Vec3d{x, y, 3 * std::sin(x / 9)})));
    const Vec3d n{-3 / 9.0 * std::cos(x / 9), 0, 1};
    c.normals.push_back(toFloat(n * (1 / length(n))));
  }
  return c;
}

std::string writeCloud(const test::TempDir& dir, const Cloud& c) {
  PlyLayout layout;
  layout.vertexCount = c.points.size();
  layout.normals = true;
  std::vector<Vec3f> positions;
  for (const Vec3d& p : c.points) positions.push_back(toFloat(p));
  Result<PlyWriter> writer = PlyWriter::create(dir.file("cloud.ply"), layout);
  EXPECT_TRUE(writer.ok());
  EXPECT_TRUE(writer->writeVertices(positions, c.normals, {}).ok());
  EXPECT_TRUE(writer->finish().ok());
  return dir.file("cloud.ply");
}

ChunkInputOptions inputOptions(const test::TempDir& dir) {
  ChunkInputOptions options;
  options.workDirectory = dir.file("work");
  options.chunkBufferBytes = 1 << 16;  // flushed many times on the way
  return options;
}

struct Leaves {
  std::map<std::uint64_t, MeshPart> meshes;  // by cell index
  std::uint64_t triangles = 0;
};

Leaves loadLeaves(const ChunkWriter& chunks) {
  Leaves leaves;
  for (const auto& [index, count] : chunks.triangleCounts()) {
    Result<MeshPart> mesh = chunks.load(cellOfIndex(chunks.grid(), index));
    EXPECT_TRUE(mesh.ok());
    leaves.triangles += mesh->triangleCount();
    leaves.meshes[index] = std::move(*mesh);
  }
  return leaves;
}

// The Chunk path: every reconstruction chunk is one leaf, holding exactly the triangles the
// in-memory reconstruction makes there (no global merge, no re-cutting), and every vertex on a
// leaf's face lies on the leaf grid's plane bit for bit and exists in the leaf across it.
TEST(SurfaceInput, EachReconstructionChunkIsOneLeafWithItsFacesShared) {
  test::TempDir dir;
  const Cloud c = sheet(20'000, 3);
  const std::string path = writeCloud(dir, c);
  ReconstructOptions reconstruct;
  // Near the origin, k·N voxels from the lattice's origin and k chunk edges from the grid's
  // round apart on about half the planes at this voxel and N.
  reconstruct.voxel = 0.45;
  reconstruct.chunkVoxels = 9;
  std::vector<SurfacePiece> pieces;
  Result<ReconstructedMesh> memory =
      reconstructPoints(c.points, c.normals, {}, "sheet", reconstruct, &pieces);
  ASSERT_TRUE(memory.ok()) << memory.error().message;
  ReconstructStats stats;
  Result<ChunkInput> input = surfaceChunkInput(path, inputOptions(dir), reconstruct, stats);
  ASSERT_TRUE(input.ok()) << input.error().message;
  EXPECT_EQ(stats.points, c.points.size());
  EXPECT_EQ(stats.triangles, memory->indices.size() / 3);
  EXPECT_EQ(input->inputTriangles, stats.triangles);
  const ChunkGrid& grid = input->chunks->grid();
  EXPECT_DOUBLE_EQ(grid.size, 0.45 * 9);
  std::size_t nonEmpty = 0;
  for (const SurfacePiece& piece : pieces) nonEmpty += piece.indices.empty() ? 0 : 1;
  EXPECT_EQ(input->chunks->triangleCounts().size(), nonEmpty);
  const Leaves leaves = loadLeaves(*input->chunks);
  EXPECT_EQ(leaves.triangles, stats.triangles);
  // Face vertices lie on their plane exactly (none a rounding off it), and the leaves weld into
  // the in-memory mesh: every face vertex is the same bits on both sides.
  std::size_t onFaces = 0, nearFaces = 0;
  std::vector<MeshPart> parts;
  for (const auto& [index, mesh] : leaves.meshes) {
    const ChunkCell cell = cellOfIndex(grid, index);
    const Aabbd bounds = grid.cellBounds(cell);
    for (const Vec3d& p : mesh.positions)
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(p[a], bounds.min[a]);
        EXPECT_LE(p[a], bounds.max[a]);
        for (const std::int32_t k :
             {cell[static_cast<std::size_t>(a)], cell[static_cast<std::size_t>(a)] + 1}) {
          nearFaces += std::abs(p[a] - grid.plane(a, k)) < 1e-6 * grid.size ? 1 : 0;
          onFaces += p[a] == grid.plane(a, k) ? 1 : 0;
        }
      }
    parts.push_back(mesh);
  }
  EXPECT_GT(onFaces, 100u);
  EXPECT_EQ(onFaces, nearFaces);
  MeshPart welded = concatenate(parts);
  weldExact(welded);
  EXPECT_EQ(welded.vertexCount(), memory->positions.size());
  EXPECT_EQ(welded.triangleCount(), memory->indices.size() / 3);
  // Only the chunk files are left in the work folder.
  EXPECT_FALSE(std::filesystem::exists(dir.file("work/surface")));
}

// The points are placed by the transform before anything else (a CRS to a local frame).
TEST(SurfaceInput, ThePointsArePlacedFirst) {
  test::TempDir dir;
  const Cloud c = sheet(5'000, 4);
  const std::string path = writeCloud(dir, c);
  ReconstructOptions reconstruct;
  reconstruct.voxel = 1.5;
  ChunkInputOptions options = inputOptions(dir);
  options.transform = [](Vec3d in, Vec3d& out) {
    out = in - Vec3d{-1000, -2000, 0};
    return true;
  };
  ReconstructStats stats;
  Result<ChunkInput> input = surfaceChunkInput(path, options, reconstruct, stats);
  ASSERT_TRUE(input.ok()) << input.error().message;
  // The sheet spans x 1000…1080, y 2000…2050 there; its edge may stand a voxel past the points.
  EXPECT_NEAR(input->bounds.min.x, 1000, 1.5);
  EXPECT_NEAR(input->bounds.max.x, 1080, 1.5);
  EXPECT_NEAR(input->bounds.max.y, 2050, 1.5);
  options.transform = [](Vec3d in, Vec3d& out) {
    out = in;
    return in.x < 40;
  };
  std::filesystem::remove_all(dir.file("work"));
  Result<ChunkInput> refused = surfaceChunkInput(path, options, reconstruct, stats);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(refused.error().message.find("cannot be placed"), std::string::npos);
}

// Points too sparse for any surface at the voxel: bad input that says what would work.
TEST(SurfaceInput, NoSurfaceIsBadInput) {
  test::TempDir dir;
  const Cloud c = sheet(400, 5);
  const std::string path = writeCloud(dir, c);
  ReconstructOptions reconstruct;
  reconstruct.voxel = 0.05;  // 3 points within 0.15 m of a corner: nowhere, at 3 m spacing
  ReconstructStats stats;
  Result<ChunkInput> input = surfaceChunkInput(path, inputOptions(dir), reconstruct, stats);
  ASSERT_FALSE(input.ok());
  EXPECT_EQ(input.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(input.error().message.find("larger --voxel"), std::string::npos);
}

}  // namespace
}  // namespace lodforge
