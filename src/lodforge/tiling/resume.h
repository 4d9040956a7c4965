// What lets `lodforge tiles --resume` go on from an interrupted run (docs/tiles.md, "Resume"):
// the chunk state in the work directory (what the chunks were made from and of) and, beside each
// finished node's mesh file, a summary of the node. Both are written whole and atomically, and
// read back only when they are intact and were made from the same input and options.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_input.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

// The chunk state of a run whose work directory is `workDirectory`.
std::string workStatePath(const std::string& workDirectory);

// Bounds as [min x, y, z, max x, y, z]; reading throws nlohmann::json::exception when malformed.
nlohmann::json boundsToJson(const Aabbd& bounds);
Aabbd boundsFromJson(const nlohmann::json& json);

// After chunking: the grid, the chunk counts and `identity` (input and options), so that a later
// run with the same identity can take the chunks as they are.
Status saveChunkState(const std::string& path, const nlohmann::json& identity,
                      const ChunkInput& input);
// The chunks of an earlier run (their files in `chunkDirectory`), when its state is intact and
// its identity is `identity`; nothing otherwise (chunk again).
std::optional<ChunkInput> resumeChunks(const std::string& path, const nlohmann::json& identity,
                                       const std::string& chunkDirectory);

// A finished node's summary, beside its mesh file: written last, so its presence means done.
std::string nodeSummaryPath(const std::string& meshPath);
Status writeNodeSummary(const OctreeNode& node);
// Fills the node's bounds, error and counts from the summary at `path`; false when it is missing
// or damaged (build the node again).
bool readNodeSummary(const std::string& path, OctreeNode& node);

}  // namespace lodforge
