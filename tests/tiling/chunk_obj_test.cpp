#include "lodforge/tiling/chunk_obj.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "lodforge/io/model_io.h"
#include "lodforge/tiling/chunk_input.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

// What a chunk triangle draws: its corners' positions, texture coordinates and colours, and the
// texture it samples (its image's name: material numbers differ between readers).
// Positions as floats: the whole-file reader keeps float positions, the streamed one doubles.
// (Float arrays, not doubles holding floats: GCC 12.2's SLP vectorizer at -O2 and above drops a
// double -> float -> double round trip kept in registers.)
using Drawn =
    std::tuple<std::array<float, 9>, std::array<float, 6>, std::array<int, 9>, std::string>;

std::vector<Drawn> drawnTriangles(const ChunkInput& input) {
  std::vector<Drawn> out;
  for (const auto& [index, count] : input.chunks->triangleCounts()) {
    Result<MeshPart> mesh = input.chunks->load(cellOfIndex(input.chunks->grid(), index));
    EXPECT_TRUE(mesh.ok());
    for (std::size_t t = 0; t < mesh->indices.size(); t += 3) {
      Drawn d{};
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint32_t v = mesh->indices[t + k];
        const Vec3f p = toFloat(mesh->positions[v]);
        std::get<0>(d)[3 * k] = p.x, std::get<0>(d)[3 * k + 1] = p.y;
        std::get<0>(d)[3 * k + 2] = p.z;
        if (!mesh->colors.empty()) {
          std::get<2>(d)[3 * k] = mesh->colors[v].r, std::get<2>(d)[3 * k + 1] = mesh->colors[v].g;
          std::get<2>(d)[3 * k + 2] = mesh->colors[v].b;
        }
        if (!mesh->uvs.empty() && mesh->materials[v] != ~0u) {
          std::get<1>(d)[2 * k] = mesh->uvs[v].x, std::get<1>(d)[2 * k + 1] = mesh->uvs[v].y;
          const Material& m = input.textures.materials[mesh->materials[v]];
          std::get<3>(d) = input.textures.images[m.baseColorImage].name;
        }
      }
      // (A triangle with two corners at one point draws nothing: the streamed cut drops it.)
      const auto& q = std::get<0>(d);
      const auto same = [&](std::size_t a, std::size_t b) {
        return q[3 * a] == q[3 * b] && q[3 * a + 1] == q[3 * b + 1] && q[3 * a + 2] == q[3 * b + 2];
      };
      if (!same(0, 1) && !same(1, 2) && !same(0, 2)) out.push_back(d);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The same OBJ streamed and read whole (its objects as parts: the whole-file reader) cuts into
// the same triangles, coordinates, colours and textures, chunk for chunk; the work files go.
void expectStreamedEqualsWhole(const std::string& path, double chunkSize,
                               const test::TempDir& dir) {
  ChunkInputOptions options;
  options.chunkSize = chunkSize;
  options.vertexCacheBytes = 1;  // the smallest caches: many misses
  options.workDirectory = dir.file("streamed");
  options.parts = PartsMode::kOff;
  Result<ChunkInput> streamed = chunkInput(path, options);
  ASSERT_TRUE(streamed.ok()) << streamed.error().message;
  EXPECT_TRUE(streamed->streamed);
  options.workDirectory = dir.file("whole");
  options.parts = PartsMode::kOn;
  Result<ChunkInput> whole = chunkInput(path, options);
  ASSERT_TRUE(whole.ok()) << whole.error().message;
  EXPECT_FALSE(whole->streamed);
  EXPECT_EQ(streamed->inputTriangles, whole->inputTriangles);
  std::vector<std::uint64_t> a, b;
  for (const auto& [index, count] : streamed->chunks->triangleCounts()) a.push_back(index);
  for (const auto& [index, count] : whole->chunks->triangleCounts()) b.push_back(index);
  EXPECT_EQ(a, b);
  EXPECT_EQ(streamed->textures.images.size(), whole->textures.images.size());
  EXPECT_EQ(streamed->colors, whole->colors);
  const std::vector<Drawn> x = drawnTriangles(*streamed), y = drawnTriangles(*whole);
  EXPECT_EQ(x.size(), y.size());
  const auto [i, j] = std::mismatch(x.begin(), x.end(), y.begin(), y.end());
  if (i != x.end() && j != y.end()) {
    ADD_FAILURE() << "first difference at " << i - x.begin() << ": streamed uv "
                  << std::get<1>(*i)[0] << "," << std::get<1>(*i)[1] << " colour "
                  << std::get<2>(*i)[0] << " texture '" << std::get<3>(*i) << "' at "
                  << std::get<0>(*i)[0] << "; whole uv " << std::get<1>(*j)[0] << ","
                  << std::get<1>(*j)[1] << " colour " << std::get<2>(*j)[0] << " texture '"
                  << std::get<3>(*j) << "' at " << std::get<0>(*j)[0];
  }
  EXPECT_FALSE(fs::exists(dir.file("streamed/obj")));
}

TEST(ChunkObj, StreamedGivesTheSameChunksAsTheWholeFileReader) {
  // The horse (one connected surface: the whole-file reader keeps no segment whole) as an OBJ
  // of positions on a 2^-16 grid, which floats and doubles hold alike, so cuts agree bit for bit.
  test::TempDir dir;
  Result<Model> horse = readModel(test::dataPath("meshes/horse.ply"));
  ASSERT_TRUE(horse.ok());
  std::string text;
  for (const Vec3f& p : horse->positions) {
    const auto grid = [](float x) { return std::round(double(x) * 65536) / 65536; };
    text += fmt::format("v {} {} {}\n", grid(p.x), grid(p.y), grid(p.z));
  }
  for (std::size_t t = 0; t < horse->indices.size(); t += 3)
    text += fmt::format("f {} {} {}\n", horse->indices[t] + 1, horse->indices[t + 1] + 1,
                        horse->indices[t + 2] + 1);
  test::writeFile(dir.file("horse.obj"), text);
  expectStreamedEqualsWhole(dir.file("horse.obj"), 0.04, dir);
}

TEST(ChunkObj, TexturedStreamedGivesTheSameChunksAsTheWholeFileReader) {
  // The spider: several materials, five textures, Windows paths in its MTL.
  test::TempDir dir;
  // One chunk: the reader keeps the spider's small parts whole, which the stream cannot know.
  expectStreamedEqualsWhole(test::dataPath("textured/spider/spider.obj"), 1000, dir);
}

TEST(ChunkObj, PolygonsNegativeIndicesColoursAndNormals) {
  test::TempDir dir;
  // A quad and a pentagon by negative indices, vertex colours, a normal per corner.
  test::writeFile(dir.file("shape.obj"),
                  "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 1\n"
                  "vn 0 0 2\n"
                  "f 1//1 2//1 3//1 4//1\n"
                  "v 2 0 0 1 0 0\nv 3 0 0 1 0 0\nv 3 1 0 1 0 0\nv 2.5 2 0 1 0 0\nv 2 1 0 1 0 0\n"
                  "f -5 -4 -3 -2 -1\n");
  ChunkInputOptions options;
  options.workDirectory = dir.file("work");
  Result<ChunkInput> input = chunkInput(dir.file("shape.obj"), options);
  ASSERT_TRUE(input.ok()) << input.error().message;
  EXPECT_EQ(input->inputTriangles, 2u + 3u);
  EXPECT_TRUE(input->colors);
  std::size_t red = 0;
  for (const auto& [index, count] : input->chunks->triangleCounts()) {
    Result<MeshPart> mesh = input->chunks->load(cellOfIndex(input->chunks->grid(), index));
    ASSERT_TRUE(mesh.ok());
    for (std::size_t v = 0; v < mesh->positions.size(); ++v) {
      EXPECT_NEAR(mesh->normals[v].z, 1.0f, 1e-6);  // the file's (normalized) or the summed one
      red += mesh->positions[v].x >= 2 && mesh->colors[v] == Rgba8{255, 0, 0, 255};
    }
  }
  EXPECT_EQ(red, 5u);
}

// Triangles of one chunk's mesh as sorted position triples (positions rounded to floats).
std::vector<std::array<float, 9>> trianglesOf(const ChunkInput& input) {
  std::vector<std::array<float, 9>> out;
  for (const Drawn& d : drawnTriangles(input)) out.push_back(std::get<0>(d));
  return out;
}

double areaOf(const ChunkInput& input) {
  double area = 0;
  for (const auto& t : trianglesOf(input)) {
    const Vec3d a{t[0], t[1], t[2]}, b{t[3], t[4], t[5]}, c{t[6], t[7], t[8]};
    area += 0.5 * length(cross(b - a, c - a));
  }
  return area;
}

// A concave polygon (an L of area 3, 6 corners) is ear-clipped, not fanned: a fan from its
// first corner would cover the missing square (area 4) and fold. A face of 100 corners (a disc)
// keeps every corner; a library line of two names reads both.
TEST(ChunkObj, ConcaveAndLargePolygonsAndSeveralLibraries) {
  test::TempDir dir;
  test::writeFile(dir.file("a.mtl"), "newmtl red\nKd 1 0 0\n");
  test::writeFile(dir.file("b.mtl"), "newmtl blue\nKd 0 0 1\n");
  std::string text = "mtllib a.mtl b.mtl\n";
  // The L: (0,0) (2,0) (2,1) (1,1) (1,2) (0,2), starting at the reflex corner (1,1).
  text += "v 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nv 2 1 0\nusemtl red\nf 1 2 3 4 5 6\n";
  std::string disc = "usemtl blue\nf";
  for (int k = 0; k < 100; ++k) {
    const double angle = 2 * 3.141592653589793 * k / 100;
    text += fmt::format("v {} {} 0\n", 10 + std::cos(angle), std::sin(angle));
    disc += fmt::format(" {}", 7 + k);
  }
  test::writeFile(dir.file("shapes.obj"), text + disc + "\n");
  ChunkInputOptions options;
  options.chunkSize = 1000;
  options.workDirectory = dir.file("work");
  Result<ChunkInput> input = chunkInput(dir.file("shapes.obj"), options);
  ASSERT_TRUE(input.ok()) << input.error().message;
  EXPECT_EQ(input->inputTriangles, 4u + 98u);
  const double disc100 = 50 * std::sin(2 * 3.141592653589793 / 100);
  EXPECT_NEAR(areaOf(*input), 3.0 + disc100, 1e-4);
  EXPECT_EQ(input->sideFiles.size(), 2u);
  std::size_t red = 0, blue = 0;
  for (const Drawn& d : drawnTriangles(*input)) {
    red += std::get<2>(d)[0] == 255 && std::get<2>(d)[2] == 0;
    blue += std::get<2>(d)[0] == 0 && std::get<2>(d)[2] == 255;
  }
  EXPECT_EQ(red, 4u);
  EXPECT_EQ(blue, 98u);
}

TEST(ChunkObj, BadLinesAreRefusedNamingTheLine) {
  test::TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4"},             // past the vertices
      {"v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n", "line 3"},             // before its vertex
      {"v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", "line 2"},           // not a finite number
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "line 4"},             // index 0
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/x 2 3\n", "line 4"},           // malformed corner
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 1e39 0\nf 1 2 3\n", "line 4"},  // beyond a float
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"}};
  for (const auto& [text, expected] : cases) {
    test::writeFile(dir.file("bad.obj"), text);
    ChunkInputOptions options;
    options.workDirectory = dir.file("work");
    Result<ChunkInput> input = chunkInput(dir.file("bad.obj"), options);
    ASSERT_FALSE(input.ok()) << text;
    EXPECT_EQ(input.error().kind, ErrorKind::kBadInput) << text;
    EXPECT_NE(input.error().message.find(expected), std::string::npos)
        << text << " -> " << input.error().message;
    EXPECT_NE(input.error().message.find("bad.obj"), std::string::npos) << input.error().message;
  }
}

}  // namespace
}  // namespace lodforge
