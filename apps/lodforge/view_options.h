// What bench, render and view share: budgets ("3M", "5%") and camera paths (orbit, fly, or a
// path file) for a package.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/runtime/camera.h"
#include "lodforge/simplify/package.h"

namespace lodforge::cli {

// A vertex count (5000, 3M, 10.5M) or a share of `full` (5%).
Result<std::uint64_t> parseBudget(std::string_view text, std::uint64_t full);
// Comma-separated budgets.
Result<std::vector<std::uint64_t>> parseBudgets(const std::string& list, std::uint64_t full);
// "WIDTHxHEIGHT".
Status parseSize(const std::string& text, std::uint32_t& width, std::uint32_t& height);

struct PathChoice {
  std::string path = "orbit";  // orbit, fly, or a path file
  std::uint64_t frames = 120;  // a file's path is cut to this
  std::string size = "1280x720";
  bool sizeGiven = false;  // --size on the command line: it also overrides a path file's viewport
  double fovY = 60;
};
// The package's bounds relative to its origin.
Aabbd packageBounds(const Package& package);
Result<std::vector<Camera>> cameraPath(const PathChoice& choice, const Package& package);

}  // namespace lodforge::cli
