#include "lodforge/tiling/node_scheduler.h"

#include <mutex>
#include <optional>
#include <queue>

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "lodforge/core/progress.h"

namespace lodforge {
namespace {

// Bytes one node takes while it is built: its mesh, the simplifier, the distance grids; a
// textured one also its coordinates and materials, its surface mesh and wedge lists, and a
// texture quadric per wedge (152 B, about half a wedge a triangle).
std::uint64_t estimateBytes(std::uint64_t triangles, bool textured) {
  return triangles * (textured ? 480 : 320) + (1 << 20);
}

}  // namespace

std::uint64_t mortonOf(const ChunkCell& cell) {
  std::uint64_t morton = 0;
  for (int bit = 0; bit < 20; ++bit) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
      const auto c = static_cast<std::uint64_t>(static_cast<std::uint32_t>(cell[axis]));
      morton |= ((c >> bit) & 1) << (3 * bit + static_cast<int>(axis));
    }
  }
  return morton;
}

Status buildWhenReady(const std::vector<OctreeNode>& nodes, std::span<const std::uint32_t> parentOf,
                      std::vector<std::uint64_t>& inputTriangles, const NodeSchedule& schedule,
                      const std::function<Status(std::uint32_t)>& build) {
  const auto count = static_cast<std::uint32_t>(nodes.size());
  std::vector<std::uint32_t> pending(count, 0);
  for (std::uint32_t i = 0; i < count; ++i)
    pending[i] = static_cast<std::uint32_t>(nodes[i].children.size());
  // Priority among ready nodes: parents before leaves (their children's meshes are freshest
  // in the page cache, or held in memory), then Morton order of the cell, so that siblings
  // finish close together and their parent becomes ready early.
  std::vector<std::uint64_t> morton(count);
  for (std::uint32_t i = 0; i < count; ++i) morton[i] = mortonOf(nodes[i].cell);
  const auto later = [&](std::uint32_t a, std::uint32_t b) {
    const int levelA = nodes[a].level, levelB = nodes[b].level;
    return levelA != levelB ? levelA < levelB : morton[a] > morton[b];
  };
  std::priority_queue<std::uint32_t, std::vector<std::uint32_t>, decltype(later)> ready(later);
  for (std::uint32_t i = 0; i < count; ++i)
    if (pending[i] == 0) ready.push(i);
  std::optional<Progress> progress;
  if (!schedule.quiet) progress.emplace("tiles: octree", count);
  std::mutex mutex;  // guards ready, pending, inFlight and failure
  Status failure;
  std::uint64_t inFlightBytes = 0;
  std::uint32_t inFlight = 0;
  const int threads =
      schedule.threads > 0 ? schedule.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  tbb::task_group group;
  std::function<void()> admit;  // called with the mutex held
  const auto process = [&](std::uint32_t index, std::uint64_t bytes) {
    Status status = checkCancelled();
    if (status.ok()) {
      tbb::this_task_arena::isolate([&] { status = build(index); });
    }
    if (progress) progress->advance(1);
    std::lock_guard lock(mutex);
    inFlightBytes -= bytes;
    --inFlight;
    if (!status.ok() && failure.ok()) failure = std::move(status);
    const std::uint32_t up = parentOf[index];
    if (up != kNoParent) {
      inputTriangles[up] += nodes[index].triangles;
      if (--pending[up] == 0) ready.push(up);
    }
    admit();
  };
  admit = [&] {
    while (failure.ok() && !ready.empty() && inFlight < static_cast<std::uint32_t>(threads)) {
      const std::uint32_t next = ready.top();
      const std::uint64_t bytes = estimateBytes(inputTriangles[next], schedule.textured);
      if (schedule.memoryBudget > 0 && inFlight > 0 &&
          inFlightBytes + bytes > schedule.memoryBudget)
        return;  // waits for a node in progress to finish
      ready.pop();
      inFlightBytes += bytes;
      ++inFlight;
      group.run([&process, next, bytes] { process(next, bytes); });
    }
  };
  arena.execute([&] {
    {
      std::lock_guard lock(mutex);
      admit();
    }
    group.wait();
  });
  if (progress) progress->finish();
  return failure;
}

}  // namespace lodforge
