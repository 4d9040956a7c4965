// How `lodforge tiles` spends memory and threads (large-meshes paper §3.4): the memory mode
// and, under --memory-limit, the chunk buffer, the vertex cache, the nodes in flight and the
// leaf size.
#pragma once

#include <cstdint>

#include "lodforge/core/status.h"
#include "lodforge/tiles/tile_atlas.h"
#include "lodforge/tiling/chunk_input.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

// The paper's memory modes (§3.4): one thread; every core (or --threads) with the nodes in
// flight held to kModerateNodeBytes (the paper's moderate takes 25 % of the cores instead, which
// left one of two cores idle here); every core with chunks and node meshes kept in memory.
enum class TilesMemory : std::uint8_t { kMinimal, kModerate, kUnbounded };

// The moderate mode's bound on the nodes being built at once, without --memory-limit (their
// estimated bytes, as the octree counts them): more cores build more nodes only while they fit.
inline constexpr std::uint64_t kModerateNodeBytes = std::uint64_t{512} << 20;
// Under --memory-limit, without --threads: a thread for each this much of the nodes' share.
inline constexpr std::uint64_t kNodeBytesPerThread = std::uint64_t{64} << 20;

// Sets the threads, buffers and leaf size of `input` and `octree` for `mode` and `memoryLimit`
// (bytes, 0: none; `threads` 0: the mode's default). A limit too small to work with is refused
// (kLimit) with the least that works.
Status planTilesMemory(TilesMemory mode, std::uint64_t memoryLimit, int threads,
                       ChunkInputOptions& input, OctreeOptions& octree);

// A textured input's share under `memoryLimit` (0: none; `threads` nodes in flight): the block
// cache of the source images gets a sixteenth of what is usable, and each thread's page baking an
// eighth, so a texture page's side (`maxPageSide`, the --texture-size asked for) comes down by
// powers of two until a page fits: a tile then takes more pages rather than blurring.
struct TexturePlan {
  std::uint32_t pageSide = 4096;
  std::uint64_t cacheBytes = std::uint64_t{64} << 20;
  std::uint64_t wholeImageBytes = 0;  // the most an image decoded whole may take (0: any)
};
TexturePlan planTextureMemory(std::uint64_t memoryLimit, int threads, std::uint32_t maxPageSide,
                              std::uint64_t cacheBytes);

}  // namespace lodforge
