#include "lodforge/io/mesh/ply_textures.h"

#include <gtest/gtest.h>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "texture_support.h"

namespace lodforge {
namespace {

constexpr std::string_view kVertexUvPly =
    "ply\nformat ascii 1.0\ncomment TextureFile photo.png\nelement vertex 4\n"
    "property float x\nproperty float y\nproperty float z\nproperty float s\nproperty float t\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 0.25\n3 0 1 2\n3 0 2 3\n";

TEST(PlyTextures, VertexCoordinatesAndATextureFile) {
  test::TempDir dir;
  test::writePatternPng(dir.file("photo.png"), 8, 8);
  test::writeFile(dir.file("quad.ply"), kVertexUvPly);
  std::vector<std::string> warnings;
  Result<Model> model = readPly(dir.file("quad.ply"), {.warnings = &warnings});
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_TRUE(warnings.empty());
  ASSERT_EQ(model->images.size(), 1u);
  EXPECT_EQ(model->images[0].width, 8u);
  ASSERT_EQ(model->objectCount(), 1u);
  EXPECT_EQ(model->materials[model->objects[0].material].baseColorImage, 0u);
  ASSERT_EQ(model->vertexCount(), 4u);
  // OpenGL's t up, glTF's v down.
  EXPECT_EQ(model->uvs[3], (Vec2f{0, 0.75f}));
  EXPECT_TRUE(isConsistent(*model));
}

TEST(PlyTextures, FaceCoordinatesAndTexnumbersMakeAnObjectPerTexture) {
  test::TempDir dir;
  test::writePatternPng(dir.file("a.png"), 8, 8);
  test::writePatternPng(dir.file("b.png"), 8, 8);
  PlyLayout layout{.vertexCount = 4, .faceCount = 2, .faceUvs = true};
  layout.comments = {"TextureFile a.png", "TextureFile b.png"};
  Result<PlyWriter> writer = PlyWriter::create(dir.file("two.ply"), layout);
  ASSERT_TRUE(writer.ok());
  const std::vector<Vec3f> positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  ASSERT_TRUE(writer->writeVertices(positions, {}, {}).ok());
  const std::vector<std::uint32_t> triangles = {0, 1, 2, 0, 2, 3};
  // Vertex 0 and 2 have other coordinates in each face: a seam, two vertices each.
  const std::vector<Vec2f> corners = {{0, 0},       {1, 0},       {1, 1},
                                      {0.5f, 0.5f}, {0.9f, 0.9f}, {0.5f, 0.9f}};
  const std::vector<std::uint32_t> textures = {1, 0};
  ASSERT_TRUE(writer->writeTriangles(triangles, {}, corners, textures).ok());
  ASSERT_TRUE(writer->finish().ok());
  Result<Model> model = readPly(dir.file("two.ply"));
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 2u);
  EXPECT_EQ(model->objectName(0), "two (a)");  // texnumber 0 first
  EXPECT_EQ(model->objectName(1), "two (b)");
  EXPECT_EQ(model->vertexCount(), 6u);
  const ObjectRecord& b = model->objects[1];
  EXPECT_EQ(model->images[model->materials[b.material].baseColorImage].name, "b.png");
  EXPECT_EQ(model->uvs[b.vertexOffset + 1], (Vec2f{1, 0}));
  // Written and read as the writer's PLY: the streamed reader sees the same corners.
  Result<PlyReader> reader = PlyReader::open(dir.file("two.ply"));
  ASSERT_TRUE(reader.ok());
  EXPECT_TRUE(plyTextured(reader->header()));
  EXPECT_TRUE(reader->header().hasFaceUvs);
  EXPECT_TRUE(reader->header().hasTextureNumbers);
}

TEST(PlyTextures, MissingTexturesStrayNumbersAndBadListsAreSaid) {
  test::TempDir dir;
  // The texture file is not there: a warning, and the faces drawn grey.
  test::writeFile(dir.file("quad.ply"), kVertexUvPly);
  std::vector<std::string> warnings;
  Result<Model> model = readPly(dir.file("quad.ply"), {.warnings = &warnings});
  ASSERT_TRUE(model.ok());
  EXPECT_TRUE(test::anyContains(warnings, "photo.png")) << (warnings.empty() ? "" : warnings[0]);
  EXPECT_TRUE(test::anyContains(warnings, "grey"));
  EXPECT_TRUE(model->images.empty());
  EXPECT_EQ(model->materials[model->objects[0].material].baseColor[0], 0.5f);
  // Coordinates without a texture file: a warning.
  std::string plain(kVertexUvPly);
  plain.replace(plain.find("comment TextureFile photo.png\n"), 30, "");
  test::writeFile(dir.file("plain.ply"), plain);
  warnings.clear();
  ASSERT_TRUE(readPly(dir.file("plain.ply"), {.warnings = &warnings}).ok());
  EXPECT_TRUE(test::anyContains(warnings, "no 'comment TextureFile' line"));
  // A texnumber past the files, and a texcoord list of the wrong length: bad input, named.
  const std::string faces =
      "ply\nformat ascii 1.0\ncomment TextureFile photo.png\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\nproperty list uchar int "
      "vertex_indices\nproperty list uchar float texcoord\nproperty int texnumber\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n";
  test::writeFile(dir.file("stray.ply"), faces + "3 0 1 2 6 0 0 1 0 1 1 4\n");
  Result<Model> stray = readPly(dir.file("stray.ply"));
  ASSERT_FALSE(stray.ok());
  EXPECT_NE(stray.error().message.find("texnumber 4 but the file names 1 textures"),
            std::string::npos)
      << stray.error().message;
  test::writeFile(dir.file("short.ply"), faces + "3 0 1 2 4 0 0 1 0 0\n");
  Result<Model> shortList = readPly(dir.file("short.ply"));
  ASSERT_FALSE(shortList.ok());
  EXPECT_NE(shortList.error().message.find("4 texture coordinates for 3 corners"),
            std::string::npos)
      << shortList.error().message;
}

}  // namespace
}  // namespace lodforge
