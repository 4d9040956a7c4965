#include "lodforge/io/mesh/ply_textures.h"

#include <algorithm>
#include <bit>
#include <filesystem>
#include <map>
#include <unordered_map>

#include <fmt/format.h>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/image/texture_files.h"

namespace lodforge {
namespace {

// A corner's vertex in its object: the file's vertex and its texture coordinate.
struct CornerKey {
  std::uint32_t vertex;
  Vec2f uv;
  bool operator==(const CornerKey&) const = default;
};
struct CornerHash {
  std::size_t operator()(const CornerKey& k) const {
    std::uint64_t h = k.vertex;
    h = h * 0x9E3779B97F4A7C15ull ^ std::bit_cast<std::uint32_t>(k.uv.x);
    h = h * 0x9E3779B97F4A7C15ull ^ std::bit_cast<std::uint32_t>(k.uv.y);
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

// One object: the triangles of one (object id, texture), their corners made vertices.
void addGroup(Model& model, const PlyTexturedData& data, std::span<const std::uint32_t> members,
              std::uint32_t material, const std::string& name) {
  ModelBuilder builder(model);
  builder.beginObject(name);
  std::unordered_map<CornerKey, std::uint32_t, CornerHash> local;
  for (std::uint32_t t : members) {
    std::uint32_t corner[3];
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = data.triangles[3 * std::size_t{t} + k];
      const Vec2f uv = !data.cornerUvs.empty() ? data.cornerUvs[3 * std::size_t{t} + k]
                       : !data.uvs.empty()     ? data.uvs[v]
                                               : Vec2f{};
      const auto [it, inserted] =
          local.try_emplace(CornerKey{v, uv}, static_cast<std::uint32_t>(local.size()));
      corner[k] = it->second;
      if (!inserted) continue;
      model.positions.push_back(data.positions[v]);
      if (!data.normals.empty()) model.normals.push_back(data.normals[v]);
      if (!data.colors.empty()) model.colors.push_back(data.colors[v]);
      model.uvs.push_back(uv);
    }
    builder.addTriangle(corner[0], corner[1], corner[2]);
  }
  builder.endObject();
  model.objects.back().material = material;
}

}  // namespace

bool plyTextured(const PlyHeader& header) {
  return !header.textureFiles.empty() && (header.hasUvs || header.hasFaceUvs);
}

PlyTextures readPlyTextures(const PlyHeader& header, const std::string& path,
                            std::vector<std::string>* warnings) {
  PlyTextures out;
  std::string directory = std::filesystem::path(path).parent_path().string();
  directory = directory.empty() ? "./" : directory + "/";
  for (const std::string& file : header.textureFiles) {
    Material material;
    material.name = std::filesystem::path(file).stem().string();
    material.roughness = 1;
    material.doubleSided = true;
    bool guessed = false;
    ImageSource image{.name = file, .path = findTextureFile(file, {directory}, guessed)};
    const Status status =
        image.path.empty() ? Status(badInput(file, "texture image not found")) : probeImage(image);
    if (!status.ok()) {
      if (warnings)
        warnings->push_back(fmt::format("{}: texture {}: {}; its faces are drawn grey", path,
                                        out.materials.size(), status.error().message));
      material.baseColor = {0.5f, 0.5f, 0.5f, 1};
    } else {
      if (guessed && warnings)
        warnings->push_back(
            fmt::format("{}: texture '{}' is not there; the file of that name "
                        "beside the model is used ({})",
                        path, file, image.path));
      material.baseColorImage = static_cast<std::uint32_t>(out.images.size());
      out.images.push_back(std::move(image));
    }
    out.materials.push_back(std::move(material));
  }
  return out;
}

Status addTexturedPly(Model& model, const PlyTexturedData& data, PlyTextures textures,
                      const std::string& name) {
  const std::size_t triangleCount = data.triangles.size() / 3;
  // Triangles by (object id, texture), in ascending order of both.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> groups;
  for (std::size_t t = 0; t < triangleCount; ++t) {
    const std::uint32_t texture = data.triangleTextures.empty() ? 0 : data.triangleTextures[t];
    if (texture >= textures.materials.size() && texture != ~0u)
      return badInput(name, fmt::format("face {}: texnumber {} but the file names {} textures "
                                        "(comment TextureFile)",
                                        t, texture, textures.materials.size()));
    const std::uint32_t object = data.triangleObjects.empty() ? 0 : data.triangleObjects[t];
    groups[{object, texture}].push_back(static_cast<std::uint32_t>(t));
  }
  const std::string stem = std::filesystem::path(name).stem().string();
  const std::uint32_t firstMaterial = static_cast<std::uint32_t>(model.materials.size());
  for (const auto& [key, members] : groups) {
    const std::string base =
        data.triangleObjects.empty() ? stem : fmt::format("object {}", key.first);
    const bool none = key.second == ~0u;  // faces of no texture
    const std::string label = none ? "untextured" : textures.materials[key.second].name;
    addGroup(model, data, members, none ? kNoMaterial : firstMaterial + key.second,
             textures.materials.size() > 1 || none ? fmt::format("{} ({})", base, label) : base);
  }
  const std::uint32_t firstImage = static_cast<std::uint32_t>(model.images.size());
  for (Material& m : textures.materials) {
    if (m.baseColorImage != kNoImage) m.baseColorImage += firstImage;
    model.materials.push_back(std::move(m));
  }
  for (ImageSource& image : textures.images) model.images.push_back(std::move(image));
  dropUnusedMaterials(model);
  return {};
}

}  // namespace lodforge
