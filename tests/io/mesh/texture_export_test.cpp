#include "lodforge/io/mesh/texture_export.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <tuple>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/model_io.h"
#include "test_support.h"
#include "texture_support.h"

namespace lodforge {
namespace {

// Every corner as (world position, texture coordinate, image bytes), sorted: what a model draws,
// whatever order a format keeps vertices and images in.
using Corner = std::tuple<long, long, long, float, float, std::size_t>;
std::vector<Corner> drawnCorners(const Model& model) {
  std::vector<Corner> out;
  std::vector<std::size_t> imageHash;
  for (const ImageSource& image : model.images) {
    Result<std::vector<std::byte>> bytes = imageBytes(image);
    EXPECT_TRUE(bytes.ok());
    imageHash.push_back(std::hash<std::string_view>{}(
        std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size())));
  }
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    const ObjectRecord& r = model.objects[o];
    const std::uint32_t image =
        r.material < model.materials.size() ? model.materials[r.material].baseColorImage : kNoImage;
    for (std::uint32_t i : model.objectIndices(o)) {
      const Vec3d p = model.origin + toDouble(model.positions[r.vertexOffset + i]);
      const Vec2f uv = model.hasUvs() ? model.uvs[r.vertexOffset + i] : Vec2f{};
      out.emplace_back(std::lround(p.x * 1000), std::lround(p.y * 1000), std::lround(p.z * 1000),
                       uv.x, uv.y, image == kNoImage ? 0 : imageHash[image]);
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(TextureExport, ObjAndPlyWriteTheirImagesBesideAndReadBackTheSameDrawing) {
  Result<Model> spider = readModel(test::dataPath("textured/spider/spider.obj"));
  ASSERT_TRUE(spider.ok());
  const std::vector<Corner> expected = drawnCorners(*spider);
  test::TempDir dir;
  for (const char* name : {"spider.obj", "spider.ply", "spider.glb"}) {
    ASSERT_TRUE(writeModel(*spider, dir.file(name)).ok()) << name;
    std::vector<std::string> warnings;
    Result<Model> back = readModel(dir.file(name), {.warnings = &warnings, .cad = {}});
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_TRUE(warnings.empty()) << name << ": " << warnings.front();
    EXPECT_EQ(back->images.size(), spider->images.size()) << name;
    EXPECT_EQ(drawnCorners(*back), expected) << name;
  }
  // The OBJ's library and the images sit beside it under the model's name.
  EXPECT_TRUE(std::filesystem::exists(dir.file("spider.mtl")));
  EXPECT_TRUE(std::filesystem::exists(dir.file("spider_texture0.jpg")));
  // A second write of the same model finds its own files there and goes on.
  EXPECT_TRUE(writeModel(*spider, dir.file("spider.obj")).ok());
}

TEST(TextureExport, AFileInAnImagesPlaceIsNeverReplacedAndNothingIsWritten) {
  Result<Model> spider = readModel(test::dataPath("textured/spider/spider.obj"));
  ASSERT_TRUE(spider.ok());
  test::TempDir dir;
  test::writeFile(dir.file("mine_texture2.jpg"), "not an image of the model");
  const Status status = writeModel(*spider, dir.file("mine.obj"));
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().kind, ErrorKind::kUsage);
  EXPECT_NE(status.error().message.find("mine_texture2.jpg"), std::string::npos);
  EXPECT_EQ(test::readFile(dir.file("mine_texture2.jpg")), "not an image of the model");
  // Checked before anything was written: no other image, no library, no OBJ.
  EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{"mine_texture2.jpg"});
  // A foreign material library likewise: no image written before it is found.
  std::filesystem::remove(dir.file("mine_texture2.jpg"));
  test::writeFile(dir.file("mine.mtl"), "newmtl theirs\n");
  ASSERT_FALSE(writeModel(*spider, dir.file("mine.obj")).ok());
  EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{"mine.mtl"});
}

// A TGA texture (common beside OBJ and 3DS files) is read, written beside an OBJ as a TGA, and
// embedded in a GLB as a PNG (glTF holds no TGA) with the same texels.
TEST(TextureExport, ATgaTextureGoesBesideAnObjAndIntoAGlbAsPng) {
  test::TempDir dir;
  Image texels(6, 4);
  for (std::size_t i = 0; i < texels.rgba.size(); ++i)
    texels.rgba[i] = static_cast<std::uint8_t>(i % 4 == 3 ? 255 : i * 11);
  std::filesystem::create_directories(dir.file("in"));
  std::filesystem::create_directories(dir.file("out"));
  test::writeFile(dir.file("in/wood.tga"), test::tgaOf(texels, false));
  test::writeFile(dir.file("in/box.mtl"), "newmtl wood\nKd 1 1 1\nmap_Kd wood.tga\n");
  test::writeFile(dir.file("in/box.obj"),
                  "mtllib box.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                  "usemtl wood\nf 1/1 2/2 3/3\n");
  std::vector<std::string> warnings;
  ReadOptions read;
  read.warnings = &warnings;
  Result<Model> box = readModel(dir.file("in/box.obj"), read);
  ASSERT_TRUE(box.ok()) << box.error().message;
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  ASSERT_EQ(box->images.size(), 1u);
  EXPECT_EQ(box->images[0].format, ImageFormat::kTga);
  ASSERT_TRUE(writeModel(*box, dir.file("out/box.obj")).ok());
  EXPECT_EQ(test::readFile(dir.file("out/box_texture0.tga")),
            test::readFile(dir.file("in/wood.tga")));
  ASSERT_TRUE(writeModel(*box, dir.file("out/box.glb")).ok());
  Result<Model> glb = readModel(dir.file("out/box.glb"));
  ASSERT_TRUE(glb.ok()) << glb.error().message;
  ASSERT_EQ(glb->images.size(), 1u);
  EXPECT_EQ(glb->images[0].format, ImageFormat::kPng);
  Result<Image> embedded = decodeImage(glb->images[0]);
  ASSERT_TRUE(embedded.ok());
  EXPECT_EQ(embedded->rgba, texels.rgba);
}

}  // namespace
}  // namespace lodforge
