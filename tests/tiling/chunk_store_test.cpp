#include "lodforge/tiling/chunk_store.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>

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

// Two parts touching at the same positions stay two parts: a feature never spreads to a
// neighbour, however the chunks cut them; all-unknown features are dropped.
TEST(WeldExact, WeldsWithinOnePartOnly) {
  MeshPart mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 0}};
  mesh.features = {4, 4, 4, 9, 9, 9, 4};
  mesh.indices = {0, 1, 2, 3, 5, 4, 6, 1, 2};  // part 4's first triangle stored twice
  weldExact(mesh);
  ASSERT_EQ(mesh.vertexCount(), 6u);  // (1,0,0) and (0,1,0) once per part
  ASSERT_EQ(mesh.features.size(), 6u);
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    EXPECT_EQ(mesh.features[mesh.indices[t]], mesh.features[mesh.indices[t + 1]]);
    EXPECT_EQ(mesh.features[mesh.indices[t]], mesh.features[mesh.indices[t + 2]]);
  }
  EXPECT_EQ(distinctFeatures(mesh), (std::vector<std::uint32_t>{4, 9}));
  MeshPart scan;
  scan.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  scan.features = {kNoFeature, kNoFeature, kNoFeature};
  scan.indices = {0, 1, 2};
  weldExact(scan);
  EXPECT_TRUE(scan.features.empty());
  EXPECT_TRUE(distinctFeatures(scan).empty());
}

TEST(MeshFile, RoundTripsAndRefusesDamage) {
  test::TempDir dir;
  MeshPart mesh;
  mesh.positions = {{1e6 + 0.125, 2, 3}, {4, 5, 6}, {7, 8, 9.5}};
  mesh.colors = {{1, 2, 3, 4}, {5, 6, 7, 8}, {9, 10, 11, 12}};
  mesh.features = {3, 3, kNoFeature};
  mesh.indices = {0, 1, 2};
  ASSERT_TRUE(saveMesh(mesh, dir.file("m.mesh")).ok());
  Result<MeshPart> back = loadMesh(dir.file("m.mesh"));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->positions, mesh.positions);
  EXPECT_EQ(back->colors, mesh.colors);
  EXPECT_EQ(back->features, mesh.features);
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
  EXPECT_FALSE(writer.load({1, 1, 1}).ok());  // ends inside a block header
}

// A heightfield's triangles as the PLY reader hands them over: corners carry their vertex.
std::vector<std::array<CutCorner, 3>> gridTriangles(int n) {
  std::vector<std::array<CutCorner, 3>> out;
  const auto corner = [n](int x, int y) {
    const double z = 0.3 * std::sin(x * 0.7) * std::cos(y * 0.4);
    return CutCorner{{x * 0.1, y * 0.1, z},
                     {static_cast<std::uint8_t>(x), static_cast<std::uint8_t>(y), 7, 255},
                     normalizeOr(Vec3f{static_cast<float>(z), 0.2f, 1}, Vec3f{0, 0, 1}),
                     static_cast<std::uint64_t>(y * (n + 1) + x)};
  };
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      out.push_back({corner(x, y), corner(x + 1, y), corner(x + 1, y + 1)});
      out.push_back({corner(x, y), corner(x + 1, y + 1), corner(x, y + 1)});
    }
  }
  return out;
}

// Two parts of one surface (its halves), cut into chunks: every vertex read back, input or made
// by a cut, keeps its part, and the seam between the parts stays open.
TEST(ChunkWriter, CutPiecesKeepTheirPart) {
  test::TempDir dir;
  auto triangles = gridTriangles(60);
  Aabbd box;
  for (auto& t : triangles) {
    const std::uint32_t part = t[0].position.x + t[1].position.x + t[2].position.x < 9 ? 1 : 2;
    for (CutCorner& c : t) {
      c.feature = part;
      c.source += part << 20;  // one input vertex per part
      box.add(c.position);
    }
  }
  ChunkWriter writer(ChunkGrid::over(box, 1.3), dir.file("chunks"), 5000);
  for (const auto& t : triangles) ASSERT_TRUE(writer.addTriangle(t).ok());
  ASSERT_TRUE(writer.flush().ok());
  std::uint64_t seen[3] = {0, 0, 0};
  for (const auto& [index, count] : writer.triangleCounts()) {
    Result<MeshPart> chunk = writer.load(cellOfIndex(writer.grid(), index));
    ASSERT_TRUE(chunk.ok());
    ASSERT_EQ(chunk->features.size(), chunk->vertexCount());
    for (std::size_t i = 0; i < chunk->indices.size(); ++i) {
      const std::uint32_t v = chunk->indices[i];
      const std::uint32_t part = chunk->features[v];
      ASSERT_TRUE(part == 1 || part == 2);
      EXPECT_EQ(part, chunk->features[chunk->indices[i / 3 * 3]]);
      if (part == 1) {
        EXPECT_LE(chunk->positions[v].x, 3.0 + 1e-12);
      } else {
        EXPECT_GE(chunk->positions[v].x, 3.0 - 1e-12);
      }
      if (i % 3 == 0) ++seen[part];
    }
  }
  EXPECT_GT(seen[1], 0u);
  EXPECT_GT(seen[2], 0u);
}

TEST(ChunkWriter, StoresAnInputVertexOnceAndLoadsTheSameForAnyBuffer) {
  // Input vertices shared by triangles are stored once per block, cut vertices as they come;
  // however often the buffer is flushed (many small blocks or one), the chunks load the same.
  test::TempDir dir;
  const auto triangles = gridTriangles(60);
  Aabbd box;
  for (const auto& t : triangles)
    for (const CutCorner& c : t) box.add(c.position);
  const ChunkGrid grid = ChunkGrid::over(box, 2.5);  // cuts the surface into 3 x 3 chunks
  std::vector<std::unique_ptr<ChunkWriter>> writers;
  for (std::uint64_t buffer : {std::uint64_t{2000}, std::uint64_t{1} << 30}) {
    writers.push_back(
        std::make_unique<ChunkWriter>(grid, dir.file("chunks" + std::to_string(buffer)), buffer));
    for (const auto& t : triangles) ASSERT_TRUE(writers.back()->addTriangle(t).ok());
    ASSERT_TRUE(writers.back()->flush().ok());
  }
  ASSERT_EQ(writers[0]->triangleCounts(), writers[1]->triangleCounts());
  EXPECT_GT(writers[0]->triangleCounts().size(), 4u);
  std::uint64_t fileBytes = 0, pieces = 0;
  for (const auto& [index, count] : writers[1]->triangleCounts()) {
    const ChunkCell cell = cellOfIndex(grid, index);
    fileBytes += std::filesystem::file_size(writers[1]->chunkPath(cell));
    pieces += count;
    Result<MeshPart> small = writers[0]->load(cell), large = writers[1]->load(cell);
    ASSERT_TRUE(small.ok() && large.ok());
    EXPECT_EQ(small->positions, large->positions);
    EXPECT_EQ(small->indices, large->indices);
    EXPECT_EQ(small->colors, large->colors);
    EXPECT_EQ(small->normals, large->normals);
    EXPECT_EQ(large->triangleCount(), count);
  }
  // A soup takes 96 bytes a triangle; shared vertices make it under half of that.
  EXPECT_LT(fileBytes, 40 * pieces);
}

TEST(ChunkFile, RefusesDamageWithItsPosition) {
  test::TempDir dir;
  Aabbd box;
  box.add(Vec3d{0, 0, 0});
  box.add(Vec3d{10, 10, 10});
  ChunkWriter writer(ChunkGrid::over(box, 20), dir.file("chunks"), 1 << 20);
  for (const auto& t : gridTriangles(4)) ASSERT_TRUE(writer.addTriangle(t).ok());
  ASSERT_TRUE(writer.flush().ok());
  const std::string path = writer.chunkPath({0, 0, 0});
  const std::string bytes = test::readFile(path);
  ASSERT_TRUE(loadChunk(path).ok());
  const auto refused = [&](std::string damaged, const std::string& what) {
    std::ofstream(dir.file("bad.tri"), std::ios::binary | std::ios::trunc) << damaged;
    Result<MeshPart> bad = loadChunk(dir.file("bad.tri"));
    ASSERT_FALSE(bad.ok()) << what;
    EXPECT_EQ(bad.error().kind, ErrorKind::kBadInput) << what;
    EXPECT_NE(bad.error().message.find("bad.tri"), std::string::npos) << bad.error().message;
    EXPECT_NE(bad.error().message.find(what), std::string::npos) << bad.error().message;
  };
  refused(bytes.substr(0, bytes.size() - 1), "past the end");
  refused("XXXX" + bytes.substr(4), "not a chunk block");
  std::string index = bytes;
  index[index.size() - 4] = static_cast<char>(200);  // the last triangle's last corner
  refused(index, "index out of range");
  refused(bytes + bytes.substr(0, 6), "inside a block header");
  // A position that is no number (it would reach sorts and casts).
  std::string nan = bytes;
  const double notANumber = std::nan("");
  std::memcpy(nan.data() + 12, &notANumber, sizeof notANumber);  // the first record's x
  refused(nan, "not a finite number");
}

TEST(ChunkFile, TexturedRecordsCarryCoordinatesAndMaterialsAndRefuseDamage) {
  test::TempDir dir;
  Aabbd box;
  box.add(Vec3d{0, 0, 0});
  box.add(Vec3d{10, 10, 10});
  ChunkWriter writer(ChunkGrid::over(box, 20), dir.file("chunks"), 1 << 20);
  writer.setTextured(true);
  std::array<CutCorner, 3> triangle;
  for (std::size_t k = 0; k < 3; ++k) {
    triangle[k].position = {double(k == 1), double(k == 2), 0};
    triangle[k].uv = {0.25f * float(k), 0.5f};
    triangle[k].material = 7;
  }
  ASSERT_TRUE(writer.addTriangle(triangle).ok());
  ASSERT_TRUE(writer.flush().ok());
  const std::string path = writer.chunkPath({0, 0, 0});
  Result<MeshPart> back = loadChunk(path);
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->uvs.size(), 3u);
  EXPECT_EQ(back->uvs[2], (Vec2f{0.5f, 0.5f}));
  EXPECT_EQ(back->materials[0], 7u);
  // A texture coordinate that is no number is damage.
  std::string bytes = test::readFile(path);
  const float infinite = std::numeric_limits<float>::infinity();
  std::memcpy(bytes.data() + 12 + 40, &infinite, sizeof infinite);  // the first record's u
  std::ofstream(dir.file("bad.tri"), std::ios::binary) << bytes;
  Result<MeshPart> bad = loadChunk(dir.file("bad.tri"));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("texture coordinate is not a finite number"),
            std::string::npos)
      << bad.error().message;
}

}  // namespace
}  // namespace lodforge
