#include "lodforge/io/image/texture_files.h"

#include <algorithm>
#include <filesystem>
#include <string_view>
#include <system_error>

namespace lodforge {
namespace {

bool isFile(const std::string& path) {
  std::error_code error;
  return std::filesystem::is_regular_file(path, error);
}

bool isWindowsAbsolute(std::string_view name) {
  return name.size() > 2 && name[1] == ':' && (name[2] == '\\' || name[2] == '/');
}

}  // namespace

std::string findTextureFile(const std::string& name, const std::vector<std::string>& directories,
                            bool& guessed) {
  std::string slashed = name;
  std::replace(slashed.begin(), slashed.end(), '\\', '/');
  const bool absolute = slashed.starts_with('/') || isWindowsAbsolute(name);
  if (absolute && !isWindowsAbsolute(name) && isFile(slashed)) return slashed;
  if (!absolute) {
    for (const std::string& directory : directories) {
      for (const std::string& candidate : {directory + name, directory + slashed}) {
        if (isFile(candidate)) return std::filesystem::path(candidate).lexically_normal().string();
      }
    }
  }
  const std::string file = std::filesystem::path(slashed).filename().string();
  for (const std::string& directory : directories) {
    if (!file.empty() && isFile(directory + file)) {
      guessed = true;
      return std::filesystem::path(directory + file).lexically_normal().string();
    }
  }
  return {};
}

}  // namespace lodforge
