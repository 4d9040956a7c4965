// parts.json beside tileset.json, for a tileset of parts (a CAD assembly): every part with its
// id (the "id" of the tiles' property tables), name, assembly path and bounds (in the tileset's
// frame, [min x, y, z, max x, y, z], null for a part without triangles), the source, and for each
// level of the octree the parts none of its tiles holds any more (left out of coarse tiles as too
// small, dropSmallSegments), so a viewer can say what a coarse view is missing.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_input.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

inline constexpr const char* kPartsFileName = "parts.json";

// Per level (0: the leaves), the parts of `partCount` that no node of that level holds, ascending.
std::vector<std::vector<std::uint32_t>> partsMissingPerLevel(const OctreeResult& octree,
                                                             std::size_t partCount);

Status writePartsJson(const OctreeResult& octree, const PartTable& parts, const std::string& path);

}  // namespace lodforge
