// Which rank builds which octree nodes in a job of several ranks (docs/distributed.md): whole
// subtrees under one level, dealt out largest first to the least loaded rank (a subtree's work
// is the leaf triangles under it), and the levels above them, which rank 0 builds once every
// subtree is done.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/tiling/octree.h"

namespace lodforge {

inline constexpr int kBuiltAfterSubtrees = -1;

struct OctreeShare {
  int splitLevel = 0;               // the subtrees' roots are the nodes of this level
  std::vector<int> owner;           // per node: the rank that builds it, or kBuiltAfterSubtrees
  std::vector<std::uint64_t> work;  // per rank: the leaf triangles under its subtrees
};

// The share of `nodes` (as planned: leaves first, children listed) over `ranks`;
// `leafTriangles` per node (0 above the leaves). The split is the highest level whose subtrees
// leave the least loaded rank at least (1 - tolerance) of the busiest one's work, else the best
// balanced level; never the leaves while a level above them exists (the leaves are only read,
// the simplification is above them).
OctreeShare shareOctree(const std::vector<OctreeNode>& nodes,
                        std::span<const std::uint64_t> leafTriangles, int ranks,
                        double tolerance = 0.2);

// The least loaded rank's work over the busiest one's (1: perfectly even).
double shareBalance(const OctreeShare& share);

}  // namespace lodforge
