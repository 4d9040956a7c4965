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

Status writeSideFile(const std::string& path, std::string_view text) {
  Result<bool> needed = sideFileNeeded(path, text);
  if (!needed) return needed.status();
  return *needed ? writeWhole(path, text) : Status{};
}

Result<std::vector<std::string>> writeImagesBeside(const Model& model, const std::string& path) {
  const std::filesystem::path target(path);
  const std::string stem = target.stem().string();
  std::vector<std::string> names;
  std::vector<std::vector<std::byte>> contents;
  std::vector<bool> needed;
  // Every name checked before any is written: a refusal leaves nothing half done.
  for (std::size_t i = 0; i < model.images.size(); ++i) {
    Result<std::vector<std::byte>> bytes = imageBytes(model.images[i]);
    if (!bytes) return bytes.status();
    names.push_back(fmt::format("{}_texture{}.{}", stem, i, extensionOf(imageFormatOf(*bytes))));
    const std::string file = (target.parent_path() / names.back()).string();
    Result<bool> write = sideFileNeeded(
        file, std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()));
    if (!write) return write.status();
    needed.push_back(*write);
    contents.push_back(std::move(*bytes));
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!needed[i]) continue;
    LODFORGE_TRY(writeWhole(
        (target.parent_path() / names[i]).string(),
        std::string_view(reinterpret_cast<const char*>(contents[i].data()), contents[i].size())));
  }
  return names;
}

}  // namespace lodforge
