#include "lodforge/tiling/chunk_store.h"

#include <fstream>

#include <gtest/gtest.h>

#include "test_support.h"

namespace lodforge {
namespace {

TEST(WeldExact, MergesEqualPositionsKeepsTheFirstAndDropsDegenerates) {
  MeshPart mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {-0.0, 0, 0}, {5, 5, 5}};
  mesh.colors = {{1, 0, 0, 255}, {2, 0, 0, 255}, {3, 0, 0, 255}, {4, 0, 0, 255},
                 {5, 0, 0, 255}, {6, 0, 0, 255}, {7, 0, 0, 255}};
  mesh.indices = {0, 1, 2, 3, 4, 2, 5, 1, 3};  // the last one collapses to a repeated corner
  weldExact(mesh);
  ASSERT_EQ(mesh.vertexCount(), 4u);  // (5,5,5) is unused, -0 == +0, the two (1,0,0) merge
  EXPECT_EQ(mesh.indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2}));
  EXPECT_EQ(mesh.colors[1].r, 2);  // the first vertex of a group keeps its colour
  EXPECT_EQ(mesh.positions[3], (Vec3d{1, 1, 0}));
}

TEST(MeshFile, RoundTripsAndRefusesDamage) {
  test::TempDir dir;
  MeshPart mesh;
  mesh.positions = {{1e6 + 0.125, 2, 3}, {4, 5, 6}, {7, 8, 9.5}};
  mesh.colors = {{1, 2, 3, 4}, {5, 6, 7, 8}, {9, 10, 11, 12}};
  mesh.indices = {0, 1, 2};
  ASSERT_TRUE(saveMesh(mesh, dir.file("m.mesh")).ok());
  Result<MeshPart> back = loadMesh(dir.file("m.mesh"));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->positions, mesh.positions);
  EXPECT_EQ(back->colors, mesh.colors);
  EXPECT_EQ(back->indices, mesh.indices);
  // Truncated, and an index past the vertices.
  std::string bytes = test::readFile(dir.file("m.mesh"));
  std::ofstream(dir.file("short.mesh"), std::ios::binary) << bytes.substr(0, bytes.size() - 5);
  EXPECT_FALSE(loadMesh(dir.file("short.mesh")).ok());
  bytes[bytes.size() - 4] = 9;
  std::ofstream(dir.file("index.mesh"), std::ios::binary) << bytes;
  Result<MeshPart> bad = loadMesh(dir.file("index.mesh"));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("index.mesh"), std::string::npos);
}

TEST(ChunkWriter, AppendsPastItsBufferAndReadsEveryTriangleBack) {
  test::TempDir dir;
  Aabbd box;
  box.add(Vec3d{0, 0, 0});
  box.add(Vec3d{4, 4, 4});
  ChunkWriter writer(ChunkGrid::over(box, 2), dir.file("chunks"), 200);  // flushes often
  const std::array<CutCorner, 3> a = {CutCorner{{0.1, 0.1, 0.1}, {}, {0, 0, 1}},
                                      CutCorner{{1, 0.1, 0.1}, {}, {0, 0, 1}},
                                      CutCorner{{0.1, 1, 0.1}, {}, {0, 0, 1}}};
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(writer.add({0, 0, 0}, a).ok());
  ASSERT_TRUE(writer.add({1, 1, 1}, a).ok());
  ASSERT_TRUE(writer.flush().ok());
  EXPECT_EQ(writer.triangleCount(), 11u);
  EXPECT_EQ(writer.triangleCounts().size(), 2u);
  Result<MeshPart> first = writer.load({0, 0, 0});
  ASSERT_TRUE(first.ok());
  EXPECT_EQ(first->vertexCount(), 3u);  // ten copies of one triangle weld to one
  std::ofstream(writer.chunkPath({1, 1, 1}), std::ios::app) << "xx";
  EXPECT_FALSE(writer.load({1, 1, 1}).ok());  // ends inside a triangle
}

}  // namespace
}  // namespace lodforge
