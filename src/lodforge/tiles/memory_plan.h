// How `lodforge tiles` spends memory and threads (large-meshes paper §3.4): the memory mode
// and, under --memory-limit, the chunk buffer, the vertex cache, the nodes in flight and the
// leaf size.
#pragma once

#include <cstdint>

#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_input.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

// The paper's memory modes (§3.4): one thread; a few threads (25 % of the cores unless
// --threads says otherwise); every core with chunks and node meshes kept in memory.
enum class TilesMemory : std::uint8_t { kMinimal, kModerate, kUnbounded };

// Sets the threads, buffers and leaf size of `input` and `octree` for `mode` and `memoryLimit`
// (bytes, 0: none; `threads` 0: the mode's default). A limit too small to work with is refused
// (kLimit) with the least that works.
Status planTilesMemory(TilesMemory mode, std::uint64_t memoryLimit, int threads,
                       ChunkInputOptions& input, OctreeOptions& octree);

}  // namespace lodforge
