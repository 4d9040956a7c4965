#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"
#include "lodforge/io/mesh/obj_reader.h"
#include "lodforge/io/mesh/stl_reader.h"
#include "lodforge/io/mesh/stl_writer.h"
#include "test_support.h"

namespace lodforge {
namespace {

std::string binaryStl(const std::vector<std::array<Vec3f, 3>>& triangles, std::uint32_t declared,
                      const char* header = "") {
  std::string out(80, '\0');
  std::memcpy(out.data(), header, std::strlen(header));
  out.append(reinterpret_cast<const char*>(&declared), 4);
  for (const auto& t : triangles) {
    const Vec3f normal{0, 0, 1};
    out.append(reinterpret_cast<const char*>(&normal), 12);
    out.append(reinterpret_cast<const char*>(t.data()), 36);
    out.append(2, '\0');
  }
  return out;
}

TEST(StlRead, BinarySoupIsWeldedIntoAnIndexedMesh) {
  const std::vector<std::array<Vec3f, 3>> quad = {{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}},
                                                  {{{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}}};
  // A header that starts with "solid" does not fool the reader: the size says binary.
  const std::string bytes = binaryStl(quad, 2, "solid but binary");
  Result<Model> model = readStlFromMemory(test::bytesOf(bytes), "quad.stl");
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->vertexCount(), 4u);
  EXPECT_EQ(model->triangleCount(), 2u);
  EXPECT_EQ(model->objectName(0), "quad");
}

TEST(StlRead, AsciiSolidsBecomeNamedObjects) {
  const std::string text =
      "solid left part\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   "
      "vertex 0 1 0\n"
      "  endloop\n endfacet\nendsolid left part\n"
      "solid right\nfacet normal 0 0 1\nouter loop\nvertex 5 0 0\nvertex 6 0 0\nvertex 5 1 "
      "0\nendloop\nendfacet\n"
      "facet normal 0 0 1\nouter loop\nvertex 6 0 0\nvertex 6 1 0\nvertex 5 1 "
      "0\nendloop\nendfacet\nendsolid right\n";
  Result<Model> model = readStlFromMemory(test::bytesOf(text), "two.stl");
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 2u);
  EXPECT_EQ(model->objectName(0), "left part");
  EXPECT_EQ(model->objectName(1), "right");
  EXPECT_EQ(model->objects[1].vertexCount, 4u);
  EXPECT_EQ(model->objects[1].triangleCount, 2u);
}

TEST(StlRoundTrip, BunnyThroughBinaryAndAscii) {
  Result<Model> bunny = readObj(test::dataPath("meshes/stanford-bunny.obj"));
  ASSERT_TRUE(bunny.ok());
  test::TempDir dir;
  for (bool ascii : {false, true}) {
    const std::string path = dir.file(ascii ? "ascii.stl" : "binary.stl");
    ASSERT_TRUE(writeStl(*bunny, path, {ascii}).ok());
    Result<Model> back = readStl(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->triangleCount(), bunny->triangleCount());
    EXPECT_EQ(back->vertexCount(), bunny->vertexCount());  // welding restores the shared vertices
    // Same triangles, corner by corner (the weld numbers vertices by first use, like the OBJ).
    for (std::size_t i = 0; i < bunny->indices.size(); ++i) {
      ASSERT_EQ(back->positions[back->indices[i]], bunny->positions[bunny->indices[i]]) << i;
    }
  }
}

TEST(StlBadInput, ErrorsNameThePosition) {
  const std::vector<std::array<Vec3f, 3>> one = {{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}}};
  std::vector<std::array<Vec3f, 3>> nan = one;
  nan[0][1].y = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    std::string bytes;
    const char* expected;
  };
  const Case cases[] = {
      {binaryStl(one, 5),
       "byte 80: binary STL declares 5 triangles (334 bytes) but the file has 134 bytes"},
      {binaryStl(one, 4'000'000'000u), "declares 4000000000 triangles"},
      {binaryStl(nan, 1), "byte 108: triangle 0: coordinate is not finite"},
      {"short", "too short for a binary header"},
      {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0\n",
       ":5: file ends where a number was expected"},
      {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 nan\nvertex 0 1 0\n",
       ":5: coordinate is not finite"},
      {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 "
       "0\nendloop\nendfacet\n",
       "file ends inside a solid (no 'endsolid')"},
      {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex "
       "2 2 2\n",
       ":7: expected 'endloop', found 'vertex'"},
  };
  for (const Case& c : cases) {
    Result<Model> model = readStlFromMemory(test::bytesOf(c.bytes), "bad.stl");
    ASSERT_FALSE(model.ok()) << c.expected;
    EXPECT_EQ(model.error().kind, ErrorKind::kBadInput);
    EXPECT_NE(model.error().message.find(c.expected), std::string::npos) << model.error().message;
  }
}

}  // namespace
}  // namespace lodforge
