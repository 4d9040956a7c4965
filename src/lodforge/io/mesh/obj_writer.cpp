#include "lodforge/io/mesh/obj_writer.h"

#include <fmt/format.h>

#include <filesystem>

#include "lodforge/core/file.h"
#include "lodforge/io/mesh/texture_export.h"

namespace lodforge {
namespace {

// The material library beside the OBJ: a material per textured material of the model (its
// image written beside too); "" when the model has no texture.
Result<std::string> writeMaterials(const Model& model, const std::string& path) {
  if (!model.hasUvs() || model.images.empty()) return std::string();
  SideFiles files;
  Result<std::vector<std::string>> images = addImagesBeside(model, path, files);
  if (!images) return images.status();
  std::string mtl = "# written by lodforge\n";
  for (std::size_t m = 0; m < model.materials.size(); ++m) {
    const Material& material = model.materials[m];
    mtl += fmt::format("newmtl m{}\nKd {} {} {}\n", m, material.baseColor[0], material.baseColor[1],
                       material.baseColor[2]);
    if (material.baseColorImage != kNoImage) {
      const bool clamp = material.wrapS == TextureWrap::kClamp;
      mtl += fmt::format("map_Kd {}{}\n", clamp ? "-clamp on " : "",
                         (*images)[material.baseColorImage]);
    }
  }
  const std::string name = std::filesystem::path(path).stem().string() + ".mtl";
  files.add((std::filesystem::path(path).parent_path() / name).string(), std::move(mtl));
  LODFORGE_TRY(files.writeAll());
  return name;
}

bool texturedObject(const Model& model, std::size_t o) {
  const std::uint32_t m = model.objects[o].material;
  return model.hasUvs() && m < model.materials.size() &&
         model.materials[m].baseColorImage != kNoImage;
}

}  // namespace

Status writeObj(const Model& model, const std::string& path) {
  Result<std::string> library = writeMaterials(model, path);
  if (!library) return library.status();
  Result<OutputFile> file = OutputFile::create(path);
  if (!file) return file.status();
  std::string text = "# written by lodforge\n";
  if (!library->empty()) text += fmt::format("mtllib {}\n", *library);
  auto flushIfBig = [&]() -> Status {
    if (text.size() < (1 << 20)) return {};
    Status s = file->write(text.data(), text.size());
    text.clear();
    return s;
  };
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    const ObjectRecord& record = model.objects[o];
    std::string name(model.objectName(o));
    for (char& c : name) {
      if (c == '\n' || c == '\r' || c == ' ' || c == '\t') c = '_';
    }
    text += fmt::format("o {}\n", name.empty() ? fmt::format("object_{}", o) : name);
    const bool textured = !library->empty() && texturedObject(model, o);
    if (!library->empty() && record.material != kNoMaterial)
      text += fmt::format("usemtl m{}\n", record.material);
    for (std::uint64_t v = record.vertexOffset; v < record.vertexOffset + record.vertexCount; ++v) {
      // World coordinates in double: the shortest text that reads back to the same value.
      const Vec3d p = model.origin + toDouble(model.positions[v]);
      if (model.hasColors()) {
        const Rgba8 c = model.colors[v];
        text += fmt::format("v {} {} {} {} {} {}\n", p.x, p.y, p.z, c.r / 255.0, c.g / 255.0,
                            c.b / 255.0);
      } else {
        text += fmt::format("v {} {} {}\n", p.x, p.y, p.z);
      }
      if (model.hasNormals()) {
        const Vec3f n = model.normals[v];
        text += fmt::format("vn {} {} {}\n", n.x, n.y, n.z);
      }
      // Every vertex gets a vt when any has (numbering shared), OBJ's way up: v = 1 - glTF's.
      if (!library->empty())
        text += fmt::format("vt {} {}\n", model.uvs[v].x, 1.0f - model.uvs[v].y);
      LODFORGE_TRY(flushIfBig());
    }
    // OBJ indices are global and 1-based; normals share the vertex numbering.
    const auto indices = model.objectIndices(o);
    for (std::size_t t = 0; t < record.triangleCount; ++t) {
      const std::uint64_t a = indices[3 * t] + record.vertexOffset + 1;
      const std::uint64_t b = indices[3 * t + 1] + record.vertexOffset + 1;
      const std::uint64_t c = indices[3 * t + 2] + record.vertexOffset + 1;
      if (textured && model.hasNormals())
        text += fmt::format("f {0}/{0}/{0} {1}/{1}/{1} {2}/{2}/{2}\n", a, b, c);
      else if (textured)
        text += fmt::format("f {0}/{0} {1}/{1} {2}/{2}\n", a, b, c);
      else if (model.hasNormals())
        text += fmt::format("f {0}//{0} {1}//{1} {2}//{2}\n", a, b, c);
      else
        text += fmt::format("f {} {} {}\n", a, b, c);
      LODFORGE_TRY(flushIfBig());
    }
  }
  LODFORGE_TRY(file->write(text.data(), text.size()));
  return file->commit();
}

}  // namespace lodforge
