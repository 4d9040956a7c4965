#include "lodforge/core/directory.h"

#include <filesystem>

namespace lodforge {

namespace fs = std::filesystem;

ScopedDirectory::~ScopedDirectory() {
  std::error_code ignored;
  if (!path.empty()) fs::remove_all(path, ignored);
}

Status replaceDirectory(ScopedDirectory& staging, const std::string& output) {
  std::error_code error;
  if (fs::exists(output)) {
    ScopedDirectory old(output + ".old");
    fs::remove_all(old.path, error);
    fs::rename(output, old.path, error);
    if (error) return ioError(output, error.message());
  }
  fs::rename(staging.path, output, error);
  if (error) return ioError(output, error.message());
  staging.path.clear();
  return {};
}

}  // namespace lodforge
