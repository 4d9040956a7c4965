#include <gtest/gtest.h>

#include <filesystem>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/mesh/obj_reader.h"
#include "texture_support.h"

namespace lodforge {
namespace {

// One textured quad (material `tex`) and one triangle of an untextured material (`plain`).
constexpr std::string_view kQuadObj =
    "mtllib scene.mtl\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "g quad\nusemtl tex\nf 1/1 2/2 3/3 4/4\nusemtl plain\nf 2 5 3\n";

TEST(ObjMaterials, SpiderFindsItsWindowsPathedTexturesBesideTheFile) {
  std::vector<std::string> warnings;
  Result<Model> spider = readObj(test::dataPath("textured/spider/spider.obj"), &warnings);
  ASSERT_TRUE(spider.ok()) << spider.error().message;
  EXPECT_TRUE(isConsistent(*spider));
  EXPECT_TRUE(warnings.empty()) << warnings.front();  // ".\x.jpg" is a relative path, not a guess
  ASSERT_EQ(spider->images.size(), 4u);               // Brusttex's image is used by no face
  for (const ImageSource& image : spider->images) {
    EXPECT_EQ(image.format, ImageFormat::kJpeg) << image.name;
    EXPECT_TRUE(std::filesystem::exists(image.path)) << image.path;
    EXPECT_GT(image.width, 100u);
  }
  ASSERT_EQ(spider->uvs.size(), spider->vertexCount());
  std::size_t textured = 0;
  for (const ObjectRecord& o : spider->objects) {
    if (o.material != kNoMaterial && spider->materials[o.material].baseColorImage != kNoImage)
      ++textured;
  }
  EXPECT_EQ(textured, spider->objectCount());  // every group of the spider is textured
}

TEST(ObjMaterials, MapOptionsSpacesAndALibraryInAFolder) {
  test::TempDir dir;
  test::writePatternPng(dir.file("mats/tex dir/my tex.png"), 32, 16);
  test::writeFile(dir.file("mats/scene.mtl"),
                  "newmtl tex\nKd 0.3 0.3 0.3\nmap_Kd -s 2 2 1 -o 0.5 0.25 0 tex dir/my tex.png  \n"
                  "newmtl plain\nKd 1 0 0\n");
  std::string obj(kQuadObj);
  obj.replace(obj.find("scene.mtl"), 9, "mats/scene.mtl");
  test::writeFile(dir.file("scene.obj"), obj);
  std::vector<std::string> warnings;
  Result<Model> model = readObj(dir.file("scene.obj"), &warnings);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_TRUE(warnings.empty());
  ASSERT_EQ(model->images.size(), 1u);
  EXPECT_EQ(model->images[0].width, 32u);
  // The quad's group splits: its textured faces and its plain one.
  ASSERT_EQ(model->objectCount(), 2u);
  EXPECT_EQ(model->objectName(0), "quad (tex)");
  EXPECT_EQ(model->objectName(1), "quad");
  ASSERT_NE(model->objects[0].material, kNoMaterial);
  const Material& material = model->materials[model->objects[0].material];
  EXPECT_EQ(material.baseColorImage, 0u);
  EXPECT_EQ(material.baseColor, (std::array<float, 4>{1, 1, 1, 1}));  // the texture's own colour
  EXPECT_EQ(model->objects[1].material, kNoMaterial);
  // vt (1, 1) through -s 2 2 and -o 0.5 0.25: (2.5, 2.25), then v flipped to glTF's top-left.
  ASSERT_TRUE(model->hasUvs());
  const Vec2f corner = model->uvs[2];
  EXPECT_FLOAT_EQ(corner.x, 2.5f);
  EXPECT_FLOAT_EQ(corner.y, 1.0f - 2.25f);
  // The plain triangle keeps its Kd as vertex colour; the textured quad is white (neutral).
  const std::uint64_t plain = model->objects[1].vertexOffset;
  EXPECT_EQ(model->colors[plain], (Rgba8{255, 0, 0, 255}));
  EXPECT_EQ(model->colors[0], (Rgba8{255, 255, 255, 255}));
}

TEST(ObjMaterials, AMissingOrBrokenTextureIsAWarningAndAGreyMaterial) {
  for (const bool broken : {false, true}) {
    test::TempDir dir;
    if (broken) test::writeFile(dir.file("photo.png"), "this is not an image");
    test::writeFile(dir.file("scene.mtl"),
                    "newmtl tex\nKd 1 1 1\nmap_Kd photo.png\nnewmtl plain\nKd 1 0 0\n");
    test::writeFile(dir.file("scene.obj"), kQuadObj);
    std::vector<std::string> warnings;
    Result<Model> model = readObj(dir.file("scene.obj"), &warnings);
    ASSERT_TRUE(model.ok()) << model.error().message;
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_TRUE(test::anyContains(warnings, "photo.png")) << warnings[0];
    EXPECT_TRUE(test::anyContains(warnings, "grey")) << warnings[0];
    EXPECT_TRUE(
        test::anyContains(warnings, broken ? "not a JPEG, PNG, WebP, BMP or TGA" : "not found"))
        << warnings[0];
    EXPECT_TRUE(model->images.empty());
    EXPECT_FALSE(model->hasUvs());
    EXPECT_EQ(model->colors[0], (Rgba8{128, 128, 128, 255}));
  }
}

TEST(ObjMaterials, AnAbsolutePathFromAnotherMachineIsFoundBesideTheFileWithAWarning) {
  test::TempDir dir;
  test::writePatternPng(dir.file("photo.png"));
  test::writeFile(dir.file("scene.mtl"),
                  "newmtl tex\nmap_Kd C:\\Users\\someone\\Desktop\\photo.png\nnewmtl plain\n");
  test::writeFile(dir.file("scene.obj"), kQuadObj);
  std::vector<std::string> warnings;
  Result<Model> model = readObj(dir.file("scene.obj"), &warnings);
  ASSERT_TRUE(model.ok());
  ASSERT_EQ(model->images.size(), 1u);
  EXPECT_EQ(model->images[0].path, dir.file("photo.png"));
  EXPECT_TRUE(test::anyContains(warnings, "beside the model"))
      << (warnings.empty() ? "" : warnings[0]);
}

TEST(ObjMaterials, TexturedCornersWithoutCoordinatesAreCounted) {
  test::TempDir dir;
  test::writePatternPng(dir.file("photo.png"));
  test::writeFile(dir.file("scene.mtl"), "newmtl tex\nmap_Kd photo.png\n");
  test::writeFile(dir.file("scene.obj"),
                  "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nusemtl tex\nf 1/1 2 3\n");
  std::vector<std::string> warnings;
  Result<Model> model = readObj(dir.file("scene.obj"), &warnings);
  ASSERT_TRUE(model.ok());
  EXPECT_TRUE(
      test::anyContains(warnings, "2 corners of textured faces have no texture coordinate"));
  // An index past the file's vt lines is bad input, positioned.
  test::writeFile(
      dir.file("bad.obj"),
      "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nusemtl tex\nf 1/1 2/2 3/1\n");
  Result<Model> bad = readObj(dir.file("bad.obj"), &warnings);
  // A coordinate beyond a float's range is no coordinate.
  test::writeFile(
      dir.file("huge.obj"),
      "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 1e39 0\nusemtl tex\nf 1/1 2/1 3/1\n");
  Result<Model> huge = readObj(dir.file("huge.obj"), &warnings);
  ASSERT_FALSE(huge.ok());
  EXPECT_NE(huge.error().message.find("huge.obj:5: expected a finite number"), std::string::npos)
      << huge.error().message;
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("bad.obj:7: face refers to texture coordinate 2"),
            std::string::npos)
      << bad.error().message;
}

}  // namespace
}  // namespace lodforge
