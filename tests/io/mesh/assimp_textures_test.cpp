#include "lodforge/io/mesh/assimp_textures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/mesh/assimp_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

// Debian's assimp-testmodels (installed by scripts/install-deps.sh).
std::string testModel(std::string_view relative) {
  const std::string path = "/usr/share/assimp/models/" + std::string(relative);
  EXPECT_TRUE(std::filesystem::exists(path)) << "missing: " << path << " (assimp-testmodels)";
  return path;
}

TEST(AssimpTextures, AnFbxWithItsTextureEmbedded) {
  std::vector<std::string> warnings;
  Result<Model> box =
      readAssimp(testModel("FBX/embedded_ascii/box_embedded_texture_fragmented.fbx"), &warnings);
  ASSERT_TRUE(box.ok()) << box.error().message;
  EXPECT_TRUE(warnings.empty());
  ASSERT_EQ(box->images.size(), 1u);
  EXPECT_TRUE(box->images[0].embedded());
  Result<Image> texels = decodeImage(box->images[0]);
  ASSERT_TRUE(texels.ok()) << texels.error().message;
  EXPECT_EQ(texels->width, box->images[0].width);
  ASSERT_EQ(box->uvs.size(), box->vertexCount());
  EXPECT_EQ(box->materials[box->objects[0].material].baseColorImage, 0u);
  EXPECT_TRUE(isConsistent(*box));
}

TEST(AssimpTextures, AFileInAnotherCaseIsFoundWithAWarningAndAMissingOneIsSaid) {
  std::vector<std::string> warnings;
  Result<Model> cube = readAssimp(testModel("3DS/cube_with_diffuse_texture.3DS"), &warnings);
  ASSERT_TRUE(cube.ok());
  ASSERT_EQ(cube->images.size(), 1u);  // "TEST.PNG" is test.png beside it
  EXPECT_EQ(std::filesystem::path(cube->images[0].path).filename(), "test.png");
  EXPECT_TRUE(test::anyContains(warnings, "TEST.PNG")) << (warnings.empty() ? "" : warnings[0]);
  // The spider's FBX names its textures on a Windows drive that is not here.
  warnings.clear();
  Result<Model> spider = readAssimp(testModel("FBX/spider.fbx"), &warnings);
  ASSERT_TRUE(spider.ok());
  EXPECT_TRUE(spider->images.empty());
  EXPECT_TRUE(test::anyContains(warnings, "drwood2.jpg") ||
              test::anyContains(warnings, "drkwood2.jpg"));
  EXPECT_TRUE(test::anyContains(warnings, "drawn without its texture"));
}

// A TGA (Collada's duck, a real exporter's file) is read: the duck draws its texture.
TEST(AssimpTextures, TheDucksTgaTextureIsRead) {
  std::vector<std::string> warnings;
  Result<Model> duck = readAssimp(testModel("Collada/duck.dae"), &warnings);
  ASSERT_TRUE(duck.ok());
  EXPECT_FALSE(test::anyContains(warnings, "duckCM.tga")) << warnings.front();
  ASSERT_EQ(duck->images.size(), 1u);
  EXPECT_EQ(duck->images[0].format, ImageFormat::kTga);
  Result<Image> texels = decodeImage(duck->images[0]);
  ASSERT_TRUE(texels.ok()) << texels.error().message;
  EXPECT_EQ(texels->width, duck->images[0].width);
  EXPECT_GT(texels->width, 0u);
  // Not one flat colour: the texels are the picture.
  EXPECT_NE(std::count(texels->rgba.begin(), texels->rgba.end(), texels->rgba[0]),
            static_cast<std::ptrdiff_t>(texels->rgba.size()));
}

}  // namespace
}  // namespace lodforge
