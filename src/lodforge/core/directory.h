// Output directories that appear whole or not at all: work and staging folders removed when they
// go out of scope, and a finished staging folder put in place of the previous output.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "lodforge/core/status.h"

namespace lodforge {

// Removes `path` (recursively) on destruction unless `path` was cleared.
struct ScopedDirectory {
  std::string path;
  ScopedDirectory() = default;
  explicit ScopedDirectory(std::string p) : path(std::move(p)) {}
  ScopedDirectory(const ScopedDirectory&) = delete;
  ScopedDirectory& operator=(const ScopedDirectory&) = delete;
  ~ScopedDirectory();
};

// Renames the complete `staging` directory to `output`, replacing what was there (moved aside
// first, removed after), and clears `staging.path` so it is kept.
Status replaceDirectory(ScopedDirectory& staging, const std::string& output);

// Bytes in the regular files below `path` (what could not be read counts 0).
std::uint64_t directoryBytes(const std::string& path);

// Removes the entries directly in `directory` whose names `which` accepts (a run's leftovers of a
// kind); an I/O error naming the directory when one cannot be listed or removed.
Status removeFilesIn(const std::string& directory,
                     const std::function<bool(const std::string& name)>& which);

}  // namespace lodforge
