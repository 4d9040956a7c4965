#include "lodforge/io/mesh/gltf_textures.h"

#include <cmath>
#include <map>

#include <fmt/format.h>

#include "lodforge/io/image/image_codec.h"

namespace lodforge {
namespace {

// What reading one glTF's textures shares.
struct TextureReading {
  const tinygltf::Model& gltf;
  const std::string& baseDir;
  const std::string& name;
  Model& model;
  std::vector<std::string>* warnings;
  std::map<int, std::uint32_t> images;  // glTF image -> Model::images

  void warn(std::string message) const {
    if (warnings) warnings->push_back(std::move(message));
  }
};

// The image a texture draws: its source, or EXT_texture_webp's; -1 if none.
// A JSON value as a small non-negative index, or -1 (tinygltf's GetNumberAsInt casts any double).
int indexOf(const tinygltf::Value& value) {
  if (!value.IsNumber()) return -1;
  const double x = value.GetNumberAsDouble();
  return x >= 0 && x < 1e9 && x == std::floor(x) ? static_cast<int>(x) : -1;
}

int sourceOf(const tinygltf::Texture& texture) {
  if (const auto webp = texture.extensions.find("EXT_texture_webp");
      webp != texture.extensions.end() && webp->second.Has("source"))
    return indexOf(webp->second.Get("source"));
  return texture.source;
}

// A glTF image as an ImageSource: its bytes when embedded, its file's path otherwise.
Result<ImageSource> sourceImage(const TextureReading& reading, int index) {
  const tinygltf::Image& image = reading.gltf.images[static_cast<std::size_t>(index)];
  ImageSource source;
  source.name = !image.name.empty()  ? image.name
                : !image.uri.empty() ? image.uri
                                     : fmt::format("{} image {}", reading.name, index);
  if (image.bufferView >= 0) {
    const auto& views = reading.gltf.bufferViews;
    if (static_cast<std::size_t>(image.bufferView) >= views.size())
      return badInput(reading.name, fmt::format("image {}: bufferView {} does not exist", index,
                                                image.bufferView));
    const tinygltf::BufferView& view = views[static_cast<std::size_t>(image.bufferView)];
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= reading.gltf.buffers.size())
      return badInput(reading.name,
                      fmt::format("image {}: buffer {} does not exist", index, view.buffer));
    const auto& data = reading.gltf.buffers[static_cast<std::size_t>(view.buffer)].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
      return badInput(reading.name, fmt::format("image {}: bufferView {} lies outside its buffer",
                                                index, image.bufferView));
    const auto* begin = reinterpret_cast<const std::byte*>(data.data() + view.byteOffset);
    source.bytes.assign(begin, begin + view.byteLength);
  } else if (image.uri.empty()) {  // a data URI, kept by keepEncodedImage
    const auto* begin = reinterpret_cast<const std::byte*>(image.image.data());
    source.bytes.assign(begin, begin + image.image.size());
  } else if (reading.baseDir.empty()) {
    return badInput(source.name, "texture image: external files are not read here");
  } else {
    source.path = reading.baseDir + "/" + image.uri;
  }
  LODFORGE_TRY(probeImage(source));
  return source;
}

// The model's image for a glTF image, read once however many textures use it.
Result<std::uint32_t> imageOf(TextureReading& reading, int index) {
  if (const auto found = reading.images.find(index); found != reading.images.end())
    return found->second;
  if (index < 0 || static_cast<std::size_t>(index) >= reading.gltf.images.size())
    return badInput(reading.name, fmt::format("image {} does not exist", index));
  Result<ImageSource> source = sourceImage(reading, index);
  if (!source) return source.status();
  const auto at = static_cast<std::uint32_t>(reading.model.images.size());
  reading.model.images.push_back(std::move(*source));
  reading.images.emplace(index, at);
  return at;
}

// KHR_texture_transform's matrix, translation * rotation * scale (its specification's order).
std::array<double, 6> transformOf(const tinygltf::Value& ext) {
  auto number = [&](const char* key, std::size_t i, double fallback) {
    if (!ext.Has(key)) return fallback;
    const tinygltf::Value& array = ext.Get(key);
    if (!array.IsArray() || array.ArrayLen() <= i || !array.Get(static_cast<int>(i)).IsNumber())
      return fallback;
    const double value = array.Get(static_cast<int>(i)).GetNumberAsDouble();
    return std::isfinite(value) ? value : fallback;
  };
  const double ox = number("offset", 0, 0), oy = number("offset", 1, 0);
  const double sx = number("scale", 0, 1), sy = number("scale", 1, 1);
  double rotation = ext.Has("rotation") && ext.Get("rotation").IsNumber()
                        ? ext.Get("rotation").GetNumberAsDouble()
                        : 0.0;
  if (!std::isfinite(rotation)) rotation = 0;
  const double c = std::cos(rotation), s = std::sin(rotation);
  return {c * sx, s * sy, ox, -s * sx, c * sy, oy};
}

// One material's texture; false (with a warning) when it cannot be drawn.
bool readTexture(TextureReading& reading, std::size_t m, GltfTexturing& out) {
  const tinygltf::TextureInfo& info =
      reading.gltf.materials[m].pbrMetallicRoughness.baseColorTexture;
  if (info.index < 0) return false;
  const std::string material = fmt::format("material {} ('{}')", m, reading.gltf.materials[m].name);
  if (static_cast<std::size_t>(info.index) >= reading.gltf.textures.size()) {
    reading.warn(fmt::format("{}: {}: texture {} does not exist; drawn without it", reading.name,
                             material, info.index));
    return false;
  }
  const tinygltf::Texture& texture = reading.gltf.textures[static_cast<std::size_t>(info.index)];
  Result<std::uint32_t> image = imageOf(reading, sourceOf(texture));
  if (!image) {
    reading.warn(fmt::format("{}: drawn without its texture ({})", material,
                             image.status().error().message));
    return false;
  }
  Material& target = reading.model.materials[m];
  target.baseColorImage = *image;
  if (texture.sampler >= 0 &&
      static_cast<std::size_t>(texture.sampler) < reading.gltf.samplers.size()) {
    const tinygltf::Sampler& sampler =
        reading.gltf.samplers[static_cast<std::size_t>(texture.sampler)];
    target.wrapS = wrapModeOf(sampler.wrapS);
    target.wrapT = wrapModeOf(sampler.wrapT);
  }
  out.texCoord[m] = std::max(info.texCoord, 0);
  if (const auto ext = info.extensions.find("KHR_texture_transform");
      ext != info.extensions.end()) {
    out.transform[m] = transformOf(ext->second);
    if (ext->second.Has("texCoord") && indexOf(ext->second.Get("texCoord")) >= 0)
      out.texCoord[m] = indexOf(ext->second.Get("texCoord"));
  }
  return true;
}

}  // namespace

GltfTexturing readGltfTextures(const tinygltf::Model& gltf, const std::string& baseDir,
                               const std::string& name, Model& model,
                               std::vector<std::string>* warnings) {
  assert(model.materials.size() == gltf.materials.size());
  GltfTexturing out;
  out.texCoord.assign(gltf.materials.size(), -1);
  out.transform.assign(gltf.materials.size(), {1, 0, 0, 0, 1, 0});
  TextureReading reading{gltf, baseDir, name, model, warnings, {}};
  for (std::size_t m = 0; m < gltf.materials.size(); ++m) readTexture(reading, m, out);
  return out;
}

bool keepEncodedImage(tinygltf::Image* image, int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && image->uri.empty() && size > 0)
    image->image.assign(bytes, bytes + size);
  return true;
}

}  // namespace lodforge
