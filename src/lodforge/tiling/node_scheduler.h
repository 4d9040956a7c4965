// The order the octree's nodes are built in: every node as soon as its children are, on a fixed
// number of workers, under a memory budget (large-meshes paper §3.4, beyond its level-by-level
// barrier).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

inline constexpr std::uint32_t kNoParent = ~0u;

struct NodeSchedule {
  int threads = 0;                 // workers (0: as many as the process allows)
  std::uint64_t memoryBudget = 0;  // bytes the nodes in progress may take (0: no limit)
  // A textured node also holds its texture coordinates, wedges and their texture quadrics.
  bool textured = false;
  bool quiet = false;  // no progress shown
};

// Calls build(i) for every node i of `nodes` (children listed in each node), each once all its
// children's builds have returned. Priority among ready nodes: parents before leaves (their
// children's meshes are freshest), then Morton order of the cell, so that siblings finish close
// together. With a budget, a node starts only while the nodes in progress and it fit (or nothing
// else is in progress); `inputTriangles` (per node, what it is built from) estimates its bytes
// and grows by each child's triangles as children finish. Each build is isolated: a worker
// waiting inside it never picks up another node (two nodes' memory on one stack). The first
// failure wins; nothing new starts after it, and Ctrl-C stops it the same way.
Status buildWhenReady(const std::vector<OctreeNode>& nodes, std::span<const std::uint32_t> parentOf,
                      std::vector<std::uint64_t>& inputTriangles, const NodeSchedule& schedule,
                      const std::function<Status(std::uint32_t)>& build);

// A cell's Morton code (20 bits per axis, interleaved): siblings are neighbours in it.
std::uint64_t mortonOf(const ChunkCell& cell);

}  // namespace lodforge
