// `lodforge compare` on two meshes: their surface distance (compare.cpp hands over).
#pragma once

#include <cstdint>
#include <string>

#include "cli.h"

namespace lodforge::cli {

// Whether both are mesh files (by extension) rather than PNGs or folders.
bool isMeshComparison(const std::string& a, const std::string& b);
Status runCompareMeshes(const Global& global, const std::string& a, const std::string& b,
                        std::uint32_t samples, const std::string& json);

}  // namespace lodforge::cli
