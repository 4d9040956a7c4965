#include "lodforge/core/directory.h"

#include <filesystem>
#include <vector>

#include <fmt/format.h>

#include "lodforge/core/file.h"

namespace lodforge {

namespace fs = std::filesystem;

ScopedDirectory::~ScopedDirectory() {
  std::error_code ignored;
  if (!path.empty()) fs::remove_all(path, ignored);
}

Status replaceDirectory(ScopedDirectory& staging, const std::string& output) {
  std::error_code error;
  if (fs::exists(output, error)) {
    // Aside under a fresh name of our own (never a name the user may hold), removed after.
    ScopedDirectory old(temporaryPathFor(output));
    fs::rename(output, old.path, error);
    if (error) {
      old.path.clear();
      return ioError(output, error.message());
    }
  }
  fs::rename(staging.path, output, error);
  if (error) return ioError(output, error.message());
  staging.path.clear();
  return {};
}

std::uint64_t directoryBytes(const std::string& path) {
  std::uint64_t bytes = 0;
  std::error_code error;
  fs::recursive_directory_iterator it(path, error), end;
  for (; !error && it != end; it.increment(error)) {
    std::error_code failed;
    if (!it->is_regular_file(failed)) continue;
    const std::uintmax_t size = it->file_size(failed);
    if (!failed) bytes += size;
  }
  return bytes;
}

Status removeFilesIn(const std::string& directory,
                     const std::function<bool(const std::string& name)>& which) {
  std::error_code error;
  std::vector<fs::path> matched;  // listed first: removing while iterating skips entries
  for (fs::directory_iterator at(directory, error), end; !error && at != end; at.increment(error))
    if (which(at->path().filename().string())) matched.push_back(at->path());
  for (const fs::path& path : matched)
    if (!error) fs::remove(path, error);
  if (error) return ioError(directory, fmt::format("cannot clear: {}", error.message()));
  return {};
}

}  // namespace lodforge
