#include "lodforge/io/image/texture_files.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string_view>
#include <system_error>

namespace lodforge {
namespace {

bool isFile(const std::string& path) {
  std::error_code error;
  return std::filesystem::is_regular_file(path, error);
}

std::string lowered(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
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
  // Made on Windows, where "TEST.PNG" is "test.png": the one file of that name in any case.
  for (const std::string& directory : directories) {
    std::error_code error;
    std::string match;
    for (const auto& entry : std::filesystem::directory_iterator(directory, error)) {
      if (!lowered(entry.path().filename().string()).empty() &&
          lowered(entry.path().filename().string()) == lowered(file) &&
          entry.is_regular_file(error)) {
        if (!match.empty()) return {};  // two files differ only in case: no guess
        match = entry.path().lexically_normal().string();
      }
    }
    if (!match.empty()) {
      guessed = true;
      return match;
    }
  }
  return {};
}

}  // namespace lodforge
