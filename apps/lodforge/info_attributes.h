// What `lodforge info` says of a LAS or LAZ file's lidar fields: each one's range over every
// point, and the points per ASPRS class (all points are read, with progress).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "lodforge/core/status.h"

namespace lodforge::cli {

// {"intensity": {"min", "max"}, …, "classification": {"2": {"name", "points"}, …}}.
Result<nlohmann::json> scanPointAttributes(const std::string& path, std::uint64_t fileBytes);
void printPointAttributes(const nlohmann::json& attributes);

}  // namespace lodforge::cli
