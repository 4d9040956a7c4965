#include "view_options.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <fmt/format.h>

#include "lodforge/core/units.h"
#include "lodforge/runtime/path.h"

namespace lodforge::cli {

Result<std::uint64_t> parseBudget(std::string_view text, std::uint64_t full) {
  if (text.ends_with('%')) {
    const std::string number(text.substr(0, text.size() - 1));
    char* end = nullptr;
    const double percent = std::strtod(number.c_str(), &end);
    if (number.empty() || end != number.c_str() + number.size() || !(percent > 0) || percent > 100)
      return Error{ErrorKind::kUsage,
                   fmt::format("--budget: '{}' is not a percentage in (0, 100]", text)};
    return static_cast<std::uint64_t>(std::llround(percent / 100.0 * static_cast<double>(full)));
  }
  const auto count = parseCount(text);
  if (!count || *count == 0)
    return Error{
        ErrorKind::kUsage,
        fmt::format("--budget: '{}' is not a vertex count (5000, 3M, 10.5M) or a percentage (5%)",
                    text)};
  return *count;
}

Result<std::vector<std::uint64_t>> parseBudgets(const std::string& list, std::uint64_t full) {
  std::vector<std::uint64_t> budgets;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    auto budget = parseBudget(std::string_view(list).substr(start, comma - start), full);
    if (!budget) return budget.status();
    budgets.push_back(*budget);
    start = comma + 1;
  }
  return budgets;
}

Status parseSize(const std::string& text, std::uint32_t& width, std::uint32_t& height) {
  unsigned w = 0, h = 0;
  char x = 0;
  if (std::sscanf(text.c_str(), "%u%c%u", &w, &x, &h) != 3 || x != 'x' || w - 1 >= 16384 ||
      h - 1 >= 16384)
    return Error{ErrorKind::kUsage,
                 fmt::format("--size: '{}' is not WIDTHxHEIGHT (e.g. 1280x720)", text)};
  width = w;
  height = h;
  return {};
}

Aabbd packageBounds(const Package& package) {
  const auto& h = package.header();
  Aabbd bounds;
  bounds.add(Vec3d{h.boundsMin[0], h.boundsMin[1], h.boundsMin[2]});
  bounds.add(Vec3d{h.boundsMax[0], h.boundsMax[1], h.boundsMax[2]});
  return bounds;
}

namespace {

// The corners of every object's box (relative to the package origin), for framing.
std::vector<Vec3d> objectCorners(const Package& package) {
  std::vector<Vec3d> corners;
  corners.reserve(8 * package.objectCount());
  for (const PackageObject& o : package.objects()) {
    Aabbd box;
    box.add(Vec3d{o.boundsMin[0], o.boundsMin[1], o.boundsMin[2]});
    box.add(Vec3d{o.boundsMax[0], o.boundsMax[1], o.boundsMax[2]});
    for (int i = 0; i < 8; ++i) corners.push_back(box.corner(i));
  }
  return corners;
}

}  // namespace

Result<std::vector<Camera>> cameraPath(const PathChoice& choice, const Package& package) {
  std::uint32_t width = 0, height = 0;
  LODFORGE_TRY(parseSize(choice.size, width, height));
  const Aabbd bounds = packageBounds(package);
  const PathOptions options{
      .frames = choice.frames, .width = width, .height = height, .fovYDegrees = choice.fovY};
  if (choice.path == "orbit") return orbitPath(bounds, options);
  if (choice.path == "framed") return framedOrbitPath(bounds, objectCorners(package), options);
  if (choice.path == "fly") return flyThroughPath(bounds, options);
  auto cameras = readCameraPath(choice.path, package.origin(), bounds);
  if (cameras && cameras->size() > choice.frames) cameras->resize(choice.frames);
  if (cameras && choice.sizeGiven) {
    for (Camera& camera : *cameras) {
      camera.width = width;
      camera.height = height;
    }
  }
  return cameras;
}

}  // namespace lodforge::cli
