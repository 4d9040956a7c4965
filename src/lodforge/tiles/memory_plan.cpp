#include "lodforge/tiles/memory_plan.h"

#include <algorithm>

#include <fmt/format.h>

#include "lodforge/core/threads.h"
#include "lodforge/core/units.h"

namespace lodforge {

Status planTilesMemory(TilesMemory mode, std::uint64_t memoryLimit, int threads,
                       ChunkInputOptions& input, OctreeOptions& octree) {
  const int cores = static_cast<int>(hardwareThreads());
  switch (mode) {
    case TilesMemory::kMinimal:
      octree.threads = 1;
      input.chunkBufferBytes = std::min<std::uint64_t>(input.chunkBufferBytes, 32 << 20);
      input.vertexCacheBytes = std::min<std::uint64_t>(input.vertexCacheBytes, 32 << 20);
      break;
    case TilesMemory::kModerate:
      octree.threads = threads > 0 ? threads : std::max(1, cores);
      octree.memoryBudget = kModerateNodeBytes;
      break;
    case TilesMemory::kUnbounded:
      octree.threads = threads > 0 ? threads : cores;
      input.keepInMemory = true;
      octree.keepInMemory = true;
      break;
  }
  if (memoryLimit > 0) {
    // The program itself (code, libraries, thread stacks, I/O buffers) takes about 32 MiB; of
    // the rest a quarter goes to the chunk buffer, an eighth to the vertex cache and half to the
    // nodes in flight (the octree lowers its parallelism to fit).
    constexpr std::uint64_t kProgram = std::uint64_t{32} << 20;
    constexpr std::uint64_t kLeast = kProgram + (std::uint64_t{16} << 20);
    if (memoryLimit < kLeast)
      return Error{ErrorKind::kLimit,
                   fmt::format("--memory-limit {} is too small for tiles: at least {}",
                               formatBytes(memoryLimit), formatBytes(kLeast))};
    const std::uint64_t usable = memoryLimit - kProgram;
    input.chunkBufferBytes = std::min(input.chunkBufferBytes, usable / 4);
    input.vertexCacheBytes = std::min(input.vertexCacheBytes, usable / 8);
    octree.memoryBudget = usable / 2;
    // Each thread beyond the first costs its own buffers and a node of its own (two threads under
    // 96M peaked at 88-94 MiB, one at 68): unless --threads says otherwise, a thread for every
    // kNodeBytesPerThread of the nodes' share.
    if (threads == 0)
      octree.threads =
          static_cast<int>(std::clamp<std::uint64_t>(octree.memoryBudget / kNodeBytesPerThread, 1,
                                                     static_cast<std::uint64_t>(octree.threads)));
    // A parent holds about four children (eight in a volume) while it is simplified, at ~200
    // bytes per triangle: smaller leaves when the budget cannot hold that for the default size.
    if (input.chunkSize == 0) {
      input.trianglesPerChunk =
          std::clamp<std::uint64_t>(octree.memoryBudget / (4 * 200), 4096, input.trianglesPerChunk);
    }
    input.keepInMemory = false;
    octree.keepInMemory = false;
  }
  input.threads = octree.threads;
  return {};
}

TexturePlan planTextureMemory(std::uint64_t memoryLimit, int threads, std::uint32_t maxPageSide,
                              std::uint64_t cacheBytes) {
  TexturePlan plan{maxPageSide, cacheBytes, 0};
  if (memoryLimit == 0) return plan;
  constexpr std::uint64_t kProgram = std::uint64_t{32} << 20;  // as planTilesMemory
  const std::uint64_t usable = memoryLimit > kProgram ? memoryLimit - kProgram : 0;
  plan.cacheBytes = std::min(cacheBytes, usable / 16);
  const std::uint64_t perThread = usable / 8 / static_cast<std::uint64_t>(std::max(threads, 1));
  while (plan.pageSide > 256 && atlasPageBytes(plan.pageSide) > perThread) plan.pageSide /= 2;
  // A PNG or WebP source is decoded whole before its pyramid is built (a JPEG streams).
  plan.wholeImageBytes = usable / 2;
  return plan;
}

}  // namespace lodforge
