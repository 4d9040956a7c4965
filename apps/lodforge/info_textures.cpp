#include "info_textures.h"

#include <fmt/format.h>

#include "lodforge/core/units.h"

namespace lodforge::cli {
namespace {

const char* wrapName(TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::kMirror:
      return "mirror";
    case TextureWrap::kClamp:
      return "clamp";
    case TextureWrap::kRepeat:
      break;
  }
  return "repeat";
}

const char* channelName(std::uint32_t channels) {
  switch (channels) {
    case 1:
      return "grey";
    case 2:
      return "grey + alpha";
    case 3:
      return "RGB";
    default:
      return "RGBA";
  }
}

}  // namespace

nlohmann::json textureSummary(const Model& model) {
  if (model.images.empty()) return {};
  nlohmann::json materials = nlohmann::json::array();
  for (const Material& m : model.materials) {
    nlohmann::json entry = {{"name", m.name}};
    if (m.baseColorImage != kNoImage) {
      entry["image"] = m.baseColorImage;
      entry["wrap"] = fmt::format("{} {}", wrapName(m.wrapS), wrapName(m.wrapT));
    }
    materials.push_back(std::move(entry));
  }
  nlohmann::json images = nlohmann::json::array();
  std::uint64_t textureBytes = 0;
  for (const ImageSource& image : model.images) {
    nlohmann::json entry = {{"name", image.name},
                            {"format", std::string(imageFormatName(image.format))},
                            {"width", image.width},
                            {"height", image.height},
                            {"channels", image.channels}};
    if (image.embedded()) {
      entry["embeddedBytes"] = image.bytes.size();
    } else {
      entry["file"] = image.path;
    }
    images.push_back(std::move(entry));
    // A full mipmap chain adds a third.
    textureBytes += image.decodedBytes() * 4 / 3;
  }
  return {{"materials", materials}, {"images", images}, {"textureBytes", textureBytes}};
}

void printTextures(const nlohmann::json& textures) {
  if (textures.empty()) return;
  const nlohmann::json& materials = textures["materials"];
  std::size_t textured = 0;
  for (const nlohmann::json& m : materials)
    if (m.contains("image")) ++textured;
  fmt::print("materials  {} ({} textured)\n", materials.size(), textured);
  for (const nlohmann::json& m : materials) {
    if (!m.contains("image")) continue;
    fmt::print("  {}: image {}, {}\n", m["name"].get<std::string>(),
               m["image"].get<std::uint32_t>(), m["wrap"].get<std::string>());
  }
  const nlohmann::json& images = textures["images"];
  fmt::print("images     {}, {} decoded with mipmaps\n", images.size(),
             formatBytes(textures["textureBytes"].get<std::uint64_t>()));
  for (std::size_t i = 0; i < images.size(); ++i) {
    const nlohmann::json& image = images[i];
    fmt::print("  {} {}: {} {}x{} {}, {}\n", i, image["name"].get<std::string>(),
               image["format"].get<std::string>(), image["width"].get<std::uint32_t>(),
               image["height"].get<std::uint32_t>(),
               channelName(image["channels"].get<std::uint32_t>()),
               image.contains("file")
                   ? image["file"].get<std::string>()
                   : fmt::format("embedded, {}",
                                 formatBytes(image["embeddedBytes"].get<std::uint64_t>())));
  }
}

}  // namespace lodforge::cli
