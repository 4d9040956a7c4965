#include "lodforge/tiling/texture_state.h"

#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/checksum.h"
#include "lodforge/core/file.h"

namespace lodforge {
namespace {

std::string embeddedPath(const std::string& workDirectory, std::size_t image) {
  return fmt::format("{}/images/{}.image", workDirectory, image);
}

std::optional<TextureWrap> wrapFromJson(const nlohmann::json& value) {
  const int wrap = value.get<int>();
  if (wrap < 0 || wrap > static_cast<int>(TextureWrap::kClamp)) return std::nullopt;
  return static_cast<TextureWrap>(wrap);
}

// One image as saved; its bytes back from the work directory when embedded. Nothing when its
// file is not the one the run started from.
std::optional<ImageSource> imageFromJson(const nlohmann::json& j, std::size_t index,
                                         const std::string& workDirectory) {
  ImageSource image;
  image.name = j.at("name").get<std::string>();
  image.path = j.at("path").get<std::string>();
  const int format = j.at("format").get<int>();
  if (format < 0 || format > static_cast<int>(ImageFormat::kTga)) return std::nullopt;
  image.format = static_cast<ImageFormat>(format);
  image.width = j.at("width").get<std::uint32_t>();
  image.height = j.at("height").get<std::uint32_t>();
  image.channels = j.at("channels").get<std::uint32_t>();
  const auto bytes = j.at("bytes").get<std::uint64_t>();
  if (!image.embedded()) {
    const Result<std::uint64_t> size = fileSize(image.path);
    if (!size || *size != bytes ||
        modifiedTicks(image.path) != j.at("modified").get<std::int64_t>())
      return std::nullopt;
    return image;
  }
  Result<std::vector<std::byte>> read = readFileBytes(embeddedPath(workDirectory, index));
  if (!read || read->size() != bytes || checksum64(*read) != j.at("checksum").get<std::uint64_t>())
    return std::nullopt;
  image.bytes = std::move(*read);
  return image;
}

}  // namespace

nlohmann::json materialsToJson(const std::vector<Material>& materials) {
  nlohmann::json list = nlohmann::json::array();
  for (const Material& m : materials)
    list.push_back({m.name, m.baseColor, m.metallic, m.roughness, static_cast<int>(m.alphaMode),
                    m.alphaCutoff, m.doubleSided, m.emissive, m.baseColorImage,
                    static_cast<int>(m.wrapS), static_cast<int>(m.wrapT)});
  return list;
}

std::optional<std::vector<Material>> materialsFromJson(const nlohmann::json& list) {
  std::vector<Material> materials;
  for (const auto& m : list) {
    const int alpha = m.at(4).get<int>();
    if (alpha < 0 || alpha > 2) return std::nullopt;
    const std::optional<TextureWrap> wrapS = wrapFromJson(m.at(9)), wrapT = wrapFromJson(m.at(10));
    if (!wrapS || !wrapT) return std::nullopt;
    materials.push_back({m.at(0).get<std::string>(), m.at(1).get<std::array<float, 4>>(),
                         m.at(2).get<float>(), m.at(3).get<float>(), static_cast<AlphaMode>(alpha),
                         m.at(5).get<float>(), m.at(6).get<bool>(),
                         m.at(7).get<std::array<float, 3>>(), m.at(8).get<std::uint32_t>(), *wrapS,
                         *wrapT});
  }
  return materials;
}

Result<nlohmann::json> saveTextureTable(const TextureTable& table,
                                        const std::string& workDirectory) {
  nlohmann::json images = nlohmann::json::array();
  for (std::size_t i = 0; i < table.images.size(); ++i) {
    const ImageSource& image = table.images[i];
    nlohmann::json j = {{"name", image.name},
                        {"path", image.path},
                        {"format", static_cast<int>(image.format)},
                        {"width", image.width},
                        {"height", image.height},
                        {"channels", image.channels}};
    if (image.embedded()) {
      std::error_code error;
      std::filesystem::create_directories(workDirectory + "/images", error);
      if (error) return ioError(workDirectory + "/images", "cannot create: " + error.message());
      LODFORGE_TRY(OutputFile::writeWhole(
          embeddedPath(workDirectory, i),
          std::string_view(reinterpret_cast<const char*>(image.bytes.data()), image.bytes.size())));
      j["bytes"] = image.bytes.size();
      j["checksum"] = checksum64(image.bytes);
    } else {
      Result<std::uint64_t> size = fileSize(image.path);
      if (!size) return size.status();
      j["bytes"] = *size;
      j["modified"] = modifiedTicks(image.path);
    }
    images.push_back(std::move(j));
  }
  return nlohmann::json{{"materials", materialsToJson(table.materials)}, {"images", images}};
}

std::optional<TextureTable> loadTextureTable(const nlohmann::json& state,
                                             const std::string& workDirectory) {
  TextureTable table;
  std::optional<std::vector<Material>> materials = materialsFromJson(state.at("materials"));
  if (!materials) return std::nullopt;
  table.materials = std::move(*materials);
  const auto& images = state.at("images");
  for (std::size_t i = 0; i < images.size(); ++i) {
    std::optional<ImageSource> image = imageFromJson(images.at(i), i, workDirectory);
    if (!image) return std::nullopt;
    table.images.push_back(std::move(*image));
  }
  for (const Material& m : table.materials)
    if (m.baseColorImage != kNoImage && m.baseColorImage >= table.images.size())
      return std::nullopt;
  return table;
}

}  // namespace lodforge
