#include "lodforge/io/mesh/obj_materials.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <system_error>

#include <fmt/format.h>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/image/texture_files.h"

namespace lodforge {
namespace {

std::string trimmed(std::string_view s) {
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  return std::string(s);
}

// The image of `path` in the model's table (one entry however many materials use it), or the
// reason it cannot be used.
Result<std::uint32_t> imageOf(const std::string& path, const std::string& name, Model& model,
                              std::map<std::string, std::uint32_t>& known) {
  if (const auto it = known.find(path); it != known.end()) return it->second;
  ImageSource image;
  image.name = name;
  image.path = path;
  LODFORGE_TRY(probeImage(image));
  const auto index = static_cast<std::uint32_t>(model.images.size());
  model.images.push_back(std::move(image));
  known.emplace(path, index);
  return index;
}

Material texturedMaterial(const tinyobj::material_t& mtl, std::uint32_t image) {
  Material material;
  material.name = mtl.name;
  // The texture holds the colour: Kd (often a grey default of the exporter) would darken it.
  material.baseColor = {1, 1, 1, 1};
  material.baseColorImage = image;
  material.roughness = 1;
  material.doubleSided = true;  // as untextured OBJ meshes are drawn (GlbWriteOptions)
  if (mtl.diffuse_texopt.clamp) material.wrapS = material.wrapT = TextureWrap::kClamp;
  return material;
}

}  // namespace

Vec2f ObjTextures::toUv(int mtl, float u, float v) const {
  const std::array<float, 4>& t = transform[static_cast<std::size_t>(mtl)];
  return {u * t[0] + t[2], 1.0f - (v * t[1] + t[3])};
}

ObjTextures resolveObjTextures(std::vector<tinyobj::material_t>& materials,
                               const std::vector<std::string>& searchDirectories, Model& model,
                               std::vector<std::string>* warnings) {
  ObjTextures textures;
  textures.material.assign(materials.size(), kNoMaterial);
  textures.transform.assign(materials.size(), {1, 1, 0, 0});
  std::map<std::string, std::uint32_t> known;
  auto warn = [&](std::string message) {
    if (warnings) warnings->push_back(std::move(message));
  };
  for (std::size_t m = 0; m < materials.size(); ++m) {
    tinyobj::material_t& mtl = materials[m];
    const std::string name = trimmed(mtl.diffuse_texname);
    if (name.empty()) continue;
    bool guessed = false;
    const std::string path = findTextureFile(name, searchDirectories, guessed);
    Result<std::uint32_t> image =
        path.empty() ? Result<std::uint32_t>(badInput(name, "texture image not found"))
                     : imageOf(path, name, model, known);
    if (!image) {
      warn(fmt::format("material '{}': {}; the material is drawn grey", mtl.name,
                       image.status().error().message));
      for (auto& channel : mtl.diffuse) channel = 0.5f;
      continue;
    }
    if (guessed)
      warn(
          fmt::format("material '{}': texture '{}' is not there; the file of that name beside the "
                      "model is used ({})",
                      mtl.name, name, path));
    textures.material[m] = static_cast<std::uint32_t>(model.materials.size());
    model.materials.push_back(texturedMaterial(mtl, *image));
    const auto& o = mtl.diffuse_texopt.origin_offset;
    const auto& s = mtl.diffuse_texopt.scale;
    // (An option that is no usable number leaves the map as it is, said.)
    const auto usable = [](double x) { return std::isfinite(x) && std::abs(x) < 1e6; };
    if (usable(s[0]) && usable(s[1]) && usable(o[0]) && usable(o[1])) {
      textures.transform[m] = {static_cast<float>(s[0]), static_cast<float>(s[1]),
                               static_cast<float>(o[0]), static_cast<float>(o[1])};
    } else {
      warn(fmt::format("material '{}': map_Kd's -s or -o is no usable number; ignored", mtl.name));
    }
  }
  return textures;
}

}  // namespace lodforge
