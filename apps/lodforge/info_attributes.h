// What `lodforge info` says of a LAS or LAZ file's lidar fields: each one's range over every
// point, and the points per ASPRS class (all points are read, with progress); and of extra
// fields (LAS extra bytes, other PLY vertex properties): type, scale, range, no-data count.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodforge/core/status.h"
#include "lodforge/io/points/point_extras.h"

namespace lodforge::cli {

// The ranges of a file's extra fields over the points added.
class ExtraRanges {
 public:
  explicit ExtraRanges(const PointExtras& extras);
  void add(std::span<const std::byte> points);  // extras.stride bytes each
  // [{"name", "type", "description", "scale", "offset", "min", "max", "noData", …}, …]
  nlohmann::json json() const;

 private:
  const PointExtras& extras_;
  std::vector<double> min_, max_;
  std::vector<std::uint64_t> noData_;
};

// {"intensity": {"min", "max"}, …, "classification": {"2": {"name", "points"}, …},
//  "extras": ExtraRanges::json()}.
Result<nlohmann::json> scanPointAttributes(const std::string& path, std::uint64_t fileBytes);
void printPointAttributes(const nlohmann::json& attributes);

}  // namespace lodforge::cli
