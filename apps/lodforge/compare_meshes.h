// `lodforge compare` on two meshes: their surface distance (compare.cpp hands over).
#pragma once

#include <cstdint>
#include <string>

#include "cli.h"

namespace lodforge::cli {

// Whether either is a mesh or point cloud file (by extension) rather than a PNG or a folder:
// then both must be meshes, and runCompareMeshes says which is not.
bool isMeshComparison(const std::string& a, const std::string& b);
Status runCompareMeshes(const Global& global, const std::string& a, const std::string& b,
                        std::uint32_t samples, const std::string& json);

}  // namespace lodforge::cli
