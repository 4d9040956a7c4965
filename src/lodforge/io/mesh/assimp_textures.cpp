#include "lodforge/io/mesh/assimp_textures.h"

#include <cstring>
#include <filesystem>
#include <map>

#include <assimp/material.h>
#include <fmt/format.h>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/image/texture_files.h"

namespace lodforge {
namespace {

TextureWrap wrapOf(aiTextureMapMode mode) {
  if (mode == aiTextureMapMode_Clamp || mode == aiTextureMapMode_Decal) return TextureWrap::kClamp;
  if (mode == aiTextureMapMode_Mirror) return TextureWrap::kMirror;
  return TextureWrap::kRepeat;
}

// An embedded texture as encoded bytes: compressed ones as they are, raw texels (ARGB8888 in
// aiTexel's b, g, r, a order) encoded as PNG.
Result<std::vector<std::byte>> embeddedBytes(const aiTexture& texture, const std::string& name) {
  if (texture.pcData == nullptr) return badInput(name, "embedded texture without data");
  if (texture.mHeight == 0) {
    const auto* begin = reinterpret_cast<const std::byte*>(texture.pcData);
    std::vector<std::byte> bytes(begin, begin + texture.mWidth);
    if (std::string_view(texture.achFormatHint) != "tga") return bytes;
    // A TGA has no signature to know it by later: its texels go in as a PNG.
    Result<Image> texels = decodeImage(bytes, name + ".tga");
    if (!texels) return texels.status();
    return encodeImage(*texels, {.format = ImageFormat::kPng});
  }
  if (std::uint64_t{texture.mWidth} * texture.mHeight > kMaxTexturePixels)
    return badInput(name, "embedded texture too large");
  Image image(texture.mWidth, texture.mHeight);
  for (std::size_t i = 0; i < image.pixelCount(); ++i) {
    const aiTexel& t = texture.pcData[i];
    image.rgba[4 * i] = t.r, image.rgba[4 * i + 1] = t.g, image.rgba[4 * i + 2] = t.b;
    image.rgba[4 * i + 3] = t.a;
  }
  return encodeImage(image, {.format = ImageFormat::kPng});
}

// What reading one scene's textures shares.
struct Reading {
  const aiScene& scene;
  const std::string& path;
  std::vector<std::string> directories;
  Model& model;
  std::vector<std::string>* warnings;
  std::map<std::string, std::uint32_t> images;  // by the file's texture reference

  void warn(std::string message) const {
    if (warnings) warnings->push_back(std::move(message));
  }
};

// The image a material's texture reference names, in the model's table (read once).
Result<std::uint32_t> imageOf(Reading& r, const std::string& reference) {
  if (const auto found = r.images.find(reference); found != r.images.end()) return found->second;
  ImageSource image{.name = reference};
  if (const aiTexture* embedded = r.scene.GetEmbeddedTexture(reference.c_str())) {
    Result<std::vector<std::byte>> bytes = embeddedBytes(*embedded, r.path);
    if (!bytes) return bytes.status();
    image.name =
        fmt::format("{} ({})", reference, std::filesystem::path(r.path).filename().string());
    image.bytes = std::move(*bytes);
  } else {
    bool guessed = false;
    image.path = findTextureFile(reference, r.directories, guessed);
    if (image.path.empty()) return badInput(reference, "texture image not found");
    if (guessed)
      r.warn(
          fmt::format("{}: texture '{}' is not there; the file of that name beside the model "
                      "is used ({})",
                      r.path, reference, image.path));
  }
  LODFORGE_TRY(probeImage(image));
  const auto index = static_cast<std::uint32_t>(r.model.images.size());
  r.model.images.push_back(std::move(image));
  r.images.emplace(reference, index);
  return index;
}

}  // namespace

AssimpTexturing readAssimpTextures(const aiScene& scene, std::span<const std::uint32_t> materialOf,
                                   const std::string& path, Model& model,
                                   std::vector<std::string>* warnings) {
  AssimpTexturing out;
  out.uvChannel.assign(model.materials.size(), -1);
  std::string directory = std::filesystem::path(path).parent_path().string();
  Reading r{scene, path, {directory.empty() ? "./" : directory + "/"}, model, warnings, {}};
  for (unsigned m = 0; m < scene.mNumMaterials && m < materialOf.size(); ++m) {
    if (materialOf[m] == kNoMaterial) continue;
    const aiMaterial& material = *scene.mMaterials[m];
    const aiTextureType type = material.GetTextureCount(aiTextureType_BASE_COLOR) > 0
                                   ? aiTextureType_BASE_COLOR
                                   : aiTextureType_DIFFUSE;
    aiString reference;
    unsigned uvIndex = 0;
    aiTextureMapMode modes[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
    if (material.GetTextureCount(type) == 0 ||
        material.GetTexture(type, 0, &reference, nullptr, &uvIndex, nullptr, nullptr, modes) !=
            AI_SUCCESS)
      continue;
    Result<std::uint32_t> image = imageOf(r, reference.C_Str());
    Material& target = model.materials[materialOf[m]];
    if (!image) {
      r.warn(fmt::format("{}: material '{}' is drawn without its texture ({})", path, target.name,
                         image.status().error().message));
      continue;
    }
    target.baseColorImage = *image;
    target.wrapS = wrapOf(modes[0]);
    target.wrapT = wrapOf(modes[1]);
    out.uvChannel[materialOf[m]] = static_cast<int>(uvIndex);
  }
  return out;
}

}  // namespace lodforge
