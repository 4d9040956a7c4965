#include "lodforge/io/mesh/texture_export.h"

#include <filesystem>
#include <system_error>

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/io/image/image_codec.h"

namespace lodforge {
namespace {

std::string_view extensionOf(ImageFormat format) {
  switch (format) {
    case ImageFormat::kJpeg:
      return "jpg";
    case ImageFormat::kWebp:
      return "webp";
    case ImageFormat::kBmp:
      return "bmp";
    case ImageFormat::kTga:
      return "tga";
    default:
      break;
  }
  return "png";
}

// Whether `path` may be written with `text`: absent, or holding those bytes already.
Result<bool> sideFileNeeded(const std::string& path, std::string_view text) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return true;
  Result<std::vector<std::byte>> there = readFileBytes(path);
  const bool same =
      there && there->size() == text.size() &&
      std::equal(text.begin(), text.end(), reinterpret_cast<const char*>(there->data()));
  if (same) return false;
  return Error{ErrorKind::kUsage,
               fmt::format("{}: exists and is not what this model writes there; not replaced "
                           "(move it, or write the model elsewhere)",
                           path)};
}

Status writeWhole(const std::string& path, std::string_view text) {
  Result<OutputFile> file = OutputFile::create(path);
  if (!file) return file.status();
  LODFORGE_TRY(file->write(text.data(), text.size()));
  return file->commit();
}

}  // namespace

Status SideFiles::writeAll() const {
  std::vector<bool> needed;
  for (const auto& [path, bytes] : files_) {
    Result<bool> write = sideFileNeeded(path, bytes);
    if (!write) return write.status();
    needed.push_back(*write);
  }
  for (std::size_t i = 0; i < files_.size(); ++i)
    if (needed[i]) LODFORGE_TRY(writeWhole(files_[i].first, files_[i].second));
  return {};
}

Result<std::vector<std::string>> addImagesBeside(const Model& model, const std::string& path,
                                                 SideFiles& files) {
  const std::filesystem::path target(path);
  const std::string stem = target.stem().string();
  std::vector<std::string> names;
  for (std::size_t i = 0; i < model.images.size(); ++i) {
    Result<std::vector<std::byte>> bytes = imageBytes(model.images[i]);
    if (!bytes) return bytes.status();
    names.push_back(fmt::format("{}_texture{}.{}", stem, i, extensionOf(model.images[i].format)));
    files.add((target.parent_path() / names.back()).string(),
              std::string(reinterpret_cast<const char*>(bytes->data()), bytes->size()));
  }
  return names;
}

}  // namespace lodforge
