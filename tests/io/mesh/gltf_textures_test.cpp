#include <gtest/gtest.h>

#include <cstring>
#include <numbers>

#include <fmt/format.h>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/mesh/gltf_reader.h"
#include "texture_support.h"

namespace lodforge {
namespace {

// One triangle with two TEXCOORD sets in geo.bin; the material's texture reads set 1 through a
// KHR_texture_transform (offset (0.5, 0), a quarter turn, scale (2, 3)) and wraps mirror/clamp.
struct TransformedTriangle {
  test::TempDir dir;
  std::array<float, 6> uv1 = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};

  explicit TransformedTriangle(bool withImage = true) {
    const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const float uv0[6] = {0, 0, 1, 0, 0, 1};
    std::string bin(sizeof positions + sizeof uv0 + sizeof uv1, '\0');
    std::memcpy(bin.data(), positions, sizeof positions);
    std::memcpy(bin.data() + 36, uv0, sizeof uv0);
    std::memcpy(bin.data() + 60, uv1.data(), sizeof uv1);
    test::writeFile(dir.file("geo.bin"), bin);
    if (withImage) test::writeBytes(dir.file("tex.png"), test::patternPng(8, 4));
    test::writeFile(dir.file("scene.gltf"), fmt::format(R"({{
  "asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0, "name": "tri"}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2}},
                              "material": 0}}]}}],
  "materials": [{{"name": "photo", "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0,
     "texCoord": 0, "extensions": {{"KHR_texture_transform": {{"offset": [0.5, 0],
     "rotation": {}, "scale": [2, 3], "texCoord": 1}}}}}}}}}}],
  "textures": [{{"source": 0, "sampler": 0}}],
  "samplers": [{{"wrapS": 33648, "wrapT": 33071}}],
  "images": [{{"uri": "tex.png"}}],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
                  {{"buffer": 0, "byteOffset": 36, "byteLength": 24}},
                  {{"buffer": 0, "byteOffset": 60, "byteLength": 24}}],
  "buffers": [{{"uri": "geo.bin", "byteLength": 84}}],
  "extensionsUsed": ["KHR_texture_transform"]
}})",
                                                        std::numbers::pi / 2));
  }
};

TEST(GltfTextures, BoxTexturedHasItsEmbeddedPngAndUvs) {
  std::vector<std::string> warnings;
  Result<Model> box = readGltf(test::dataPath("textured/BoxTextured.glb"), {.warnings = &warnings});
  ASSERT_TRUE(box.ok()) << box.error().message;
  EXPECT_TRUE(warnings.empty());
  ASSERT_EQ(box->images.size(), 1u);
  const ImageSource& image = box->images[0];
  EXPECT_TRUE(image.embedded());
  EXPECT_EQ(image.format, ImageFormat::kPng);
  // The header's size is the decoded size.
  Result<Image> texels = decodeImage(image);
  ASSERT_TRUE(texels.ok());
  EXPECT_EQ(texels->width, image.width);
  EXPECT_EQ(texels->height, image.height);
  ASSERT_EQ(box->materials.size(), 1u);
  EXPECT_EQ(box->materials[0].baseColorImage, 0u);
  ASSERT_EQ(box->uvs.size(), box->vertexCount());
  // Its texture repeats: u runs to 6, kept as it is (the sampler wraps it).
  float most = 0;
  for (const Vec2f& uv : box->uvs) most = std::max({most, uv.x, uv.y});
  EXPECT_EQ(most, 6.0f);
  EXPECT_EQ(box->materials[0].wrapS, TextureWrap::kRepeat);
}

TEST(GltfTextures, TextureTransformTexCoordSetAndWrapModesAreApplied) {
  TransformedTriangle scene;
  std::vector<std::string> warnings;
  Result<Model> model = readGltf(scene.dir.file("scene.gltf"), {.warnings = &warnings});
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_TRUE(warnings.empty());
  ASSERT_EQ(model->images.size(), 1u);
  EXPECT_EQ(model->images[0].path,
            scene.dir.file("scene.gltf").substr(0, scene.dir.file("").size()) + "tex.png");
  EXPECT_EQ(model->images[0].width, 8u);
  const Material& material = model->materials[0];
  EXPECT_EQ(material.wrapS, TextureWrap::kMirror);
  EXPECT_EQ(material.wrapT, TextureWrap::kClamp);
  ASSERT_EQ(model->uvs.size(), 3u);
  for (std::size_t v = 0; v < 3; ++v) {
    // translation * rotation(90°) * scale: u' = 3 v + 0.5, v' = -2 u (of TEXCOORD_1).
    const float u = scene.uv1[2 * v], w = scene.uv1[2 * v + 1];
    EXPECT_NEAR(model->uvs[v].x, 3 * w + 0.5f, 1e-5f);
    EXPECT_NEAR(model->uvs[v].y, -2 * u, 1e-5f);
  }
}

TEST(GltfTextures, AMissingImageIsAWarningAndTheMaterialDrawsWithoutIt) {
  TransformedTriangle scene(/*withImage=*/false);
  std::vector<std::string> warnings;
  Result<Model> model = readGltf(scene.dir.file("scene.gltf"), {.warnings = &warnings});
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("tex.png"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("without its texture"), std::string::npos) << warnings[0];
  EXPECT_TRUE(model->images.empty());
  EXPECT_EQ(model->materials[0].baseColorImage, kNoImage);
  EXPECT_FALSE(model->hasUvs());
}

TEST(GltfTextures, AGlbWrittenAndReadAgainKeepsImagesUvsAndWrapModes) {
  TransformedTriangle scene;
  Result<Model> model = readGltf(scene.dir.file("scene.gltf"));
  ASSERT_TRUE(model.ok());
  ASSERT_TRUE(writeGlb(*model, scene.dir.file("again.glb")).ok());
  Result<Model> again = readGltf(scene.dir.file("again.glb"));
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_EQ(again->uvs, model->uvs);
  ASSERT_EQ(again->images.size(), 1u);
  EXPECT_TRUE(again->images[0].embedded());  // the file's bytes, now inside the GLB
  Result<std::vector<std::byte>> original = imageBytes(model->images[0]);
  ASSERT_TRUE(original.ok());
  EXPECT_EQ(again->images[0].bytes, *original);
  EXPECT_EQ(again->materials[0].wrapS, TextureWrap::kMirror);
  EXPECT_EQ(again->materials[0].wrapT, TextureWrap::kClamp);
}

TEST(GltfTextures, PrimitivesWithDifferentTexturesBecomeObjectsOfOneMaterialEach) {
  // Two copies of BoxTextured's material, each on a copy of its primitive, in one mesh.
  Result<Model> box = readGltf(test::dataPath("textured/BoxTextured.glb"));
  ASSERT_TRUE(box.ok());
  Model two = *box;
  two.materials.push_back(two.materials[0]);
  two.materials[1].name = "second";
  // Same geometry again as a second object using the second material.
  const ObjectRecord first = two.objects[0];
  ModelBuilder builder(two);
  builder.beginObject("second");
  for (std::uint32_t v = 0; v < first.vertexCount; ++v) {
    two.positions.push_back(two.positions[first.vertexOffset + v]);
    two.normals.push_back(two.normals[first.vertexOffset + v]);
    two.colors.push_back(two.colors[first.vertexOffset + v]);
    two.uvs.push_back(two.uvs[first.vertexOffset + v]);
  }
  const auto indices = two.objectIndices(0);
  const std::vector<std::uint32_t> copy(indices.begin(), indices.end());
  two.indices.insert(two.indices.end(), copy.begin(), copy.end());
  builder.endObject();
  two.objects[1].material = 1;
  ASSERT_TRUE(isConsistent(two));
  test::TempDir dir;
  ASSERT_TRUE(writeGlb(two, dir.file("two.glb"), {.shareMeshes = false}).ok());
  Result<Model> back = readGltf(dir.file("two.glb"));
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back->objectCount(), 2u);
  EXPECT_EQ(back->objects[0].material, 0u);
  EXPECT_EQ(back->objects[1].material, 1u);
  EXPECT_EQ(back->images.size(), 1u);  // one image, written once
}

}  // namespace
}  // namespace lodforge
