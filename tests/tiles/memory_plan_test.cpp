#include "lodforge/tiles/memory_plan.h"

#include <algorithm>
#include <thread>

#include <gtest/gtest.h>

#include "lodforge/core/units.h"

namespace lodforge {
namespace {

constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;

int cores() {
  return static_cast<int>(std::thread::hardware_concurrency());
}

struct Plan {
  Status status;
  ChunkInputOptions input;
  OctreeOptions octree;
};

Plan plan(TilesMemory mode, std::uint64_t memoryLimit = 0, int threads = 0,
          ChunkInputOptions input = {}) {
  Plan p{{}, std::move(input), {}};
  p.status = planTilesMemory(mode, memoryLimit, threads, p.input, p.octree);
  return p;
}

// Minimal: one thread whatever --threads says, 32 MiB chunk buffer and vertex cache (never
// raised), everything on disk.
TEST(PlanTilesMemory, MinimalIsOneThreadAndSmallBuffersOnDisk) {
  for (const int threads : {0, 1, 6}) {
    const Plan p = plan(TilesMemory::kMinimal, 0, threads);
    ASSERT_TRUE(p.status.ok());
    EXPECT_EQ(p.octree.threads, 1);
    EXPECT_EQ(p.input.threads, 1);
    EXPECT_EQ(p.input.chunkBufferBytes, 32 * kMiB);
    EXPECT_EQ(p.input.vertexCacheBytes, 32 * kMiB);
    EXPECT_FALSE(p.input.keepInMemory);
    EXPECT_FALSE(p.octree.keepInMemory);
  }
  ChunkInputOptions small;
  small.chunkBufferBytes = 8 * kMiB;
  small.vertexCacheBytes = 4 * kMiB;
  const Plan p = plan(TilesMemory::kMinimal, 0, 0, small);
  EXPECT_EQ(p.input.chunkBufferBytes, 8 * kMiB);
  EXPECT_EQ(p.input.vertexCacheBytes, 4 * kMiB);
}

// Moderate: --threads, or every core, with the nodes in flight held to a budget; buffers as
// given, on disk.
TEST(PlanTilesMemory, ModerateIsEveryCoreWithinANodeBudgetOrTheThreadsGiven) {
  const Plan every = plan(TilesMemory::kModerate);
  ASSERT_TRUE(every.status.ok());
  EXPECT_EQ(every.octree.threads, std::max(1, cores()));
  EXPECT_EQ(every.octree.memoryBudget, kModerateNodeBytes);
  EXPECT_EQ(every.input.threads, every.octree.threads);
  EXPECT_EQ(every.input.chunkBufferBytes, ChunkInputOptions{}.chunkBufferBytes);
  EXPECT_EQ(every.input.vertexCacheBytes, ChunkInputOptions{}.vertexCacheBytes);
  EXPECT_FALSE(every.input.keepInMemory);
  EXPECT_FALSE(every.octree.keepInMemory);
  const Plan given = plan(TilesMemory::kModerate, 0, 5);
  EXPECT_EQ(given.octree.threads, 5);
  EXPECT_EQ(given.input.threads, 5);
}

// Unbounded: every core (or --threads), chunks and node meshes kept in memory.
TEST(PlanTilesMemory, UnboundedIsEveryCoreInMemory) {
  const Plan all = plan(TilesMemory::kUnbounded);
  ASSERT_TRUE(all.status.ok());
  EXPECT_EQ(all.octree.threads, cores());
  EXPECT_EQ(all.input.threads, cores());
  EXPECT_TRUE(all.input.keepInMemory);
  EXPECT_TRUE(all.octree.keepInMemory);
  EXPECT_EQ(all.octree.memoryBudget, 0u);
  EXPECT_EQ(plan(TilesMemory::kUnbounded, 0, 3).octree.threads, 3);
}

// Under --memory-limit: 32 MiB for the program; of the rest a quarter to the chunk buffer, an
// eighth to the vertex cache (neither raised past what was asked), half to the nodes in flight;
// leaves small enough for a parent of four children at 200 bytes a triangle;
// nothing kept in memory, whatever the mode.
TEST(PlanTilesMemory, ALimitSplitsWhatIsLeftAfterTheProgram) {
  for (const TilesMemory mode :
       {TilesMemory::kMinimal, TilesMemory::kModerate, TilesMemory::kUnbounded}) {
    const Plan p = plan(mode, 96 * kMiB);
    ASSERT_TRUE(p.status.ok()) << p.status.error().message;
    const std::uint64_t usable = 64 * kMiB;
    EXPECT_EQ(p.input.chunkBufferBytes, usable / 4);
    EXPECT_EQ(p.input.vertexCacheBytes, usable / 8);
    EXPECT_EQ(p.octree.memoryBudget, usable / 2);
    EXPECT_EQ(p.input.trianglesPerChunk, usable / 2 / (4 * 200));
    EXPECT_FALSE(p.input.keepInMemory);
    EXPECT_FALSE(p.octree.keepInMemory);
  }
  // Without --threads, a thread for every 64 MiB of the nodes' share: one under 96M.
  EXPECT_EQ(plan(TilesMemory::kModerate, 96 * kMiB).octree.threads, 1);
  EXPECT_EQ(plan(TilesMemory::kModerate, 96 * kMiB, 2).octree.threads, 2);
  // A large limit lowers nothing below the defaults, and the leaves keep their size.
  const Plan large = plan(TilesMemory::kModerate, 4096 * kMiB);
  ASSERT_TRUE(large.status.ok());
  EXPECT_EQ(large.octree.threads, std::clamp(2032 / 64, 1, cores()));
  EXPECT_EQ(large.input.threads, large.octree.threads);
  EXPECT_EQ(large.input.chunkBufferBytes, ChunkInputOptions{}.chunkBufferBytes);
  EXPECT_EQ(large.input.vertexCacheBytes, ChunkInputOptions{}.vertexCacheBytes);
  EXPECT_EQ(large.octree.memoryBudget, 4064 * kMiB / 2);
  EXPECT_EQ(large.input.trianglesPerChunk, ChunkInputOptions{}.trianglesPerChunk);
  // The least limit: 16 MiB to share, 8 MiB of it for the nodes.
  const Plan least = plan(TilesMemory::kModerate, 48 * kMiB);
  ASSERT_TRUE(least.status.ok());
  EXPECT_EQ(least.octree.memoryBudget, 8 * kMiB);
  EXPECT_EQ(least.input.trianglesPerChunk, 8 * kMiB / 800);
  // A chunk size given keeps its leaves.
  ChunkInputOptions sized;
  sized.chunkSize = 10;
  EXPECT_EQ(plan(TilesMemory::kModerate, 96 * kMiB, 0, sized).input.trianglesPerChunk,
            ChunkInputOptions{}.trianglesPerChunk);
}

// Under 48 MiB there is nothing to work with: refused as a limit, naming the least that works.
TEST(PlanTilesMemory, ALimitUnder48MiBIsRefused) {
  for (const std::uint64_t limit : {std::uint64_t{1}, 32 * kMiB, 48 * kMiB - 1}) {
    const Plan p = plan(TilesMemory::kModerate, limit);
    ASSERT_FALSE(p.status.ok()) << limit;
    EXPECT_EQ(p.status.error().kind, ErrorKind::kLimit);
    EXPECT_EQ(p.status.error().message, "--memory-limit " + formatBytes(limit) +
                                            " is too small for tiles: at least " +
                                            formatBytes(48 * kMiB));
  }
}

}  // namespace
}  // namespace lodforge
