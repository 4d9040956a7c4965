// Which rank builds which octree nodes in a job of several ranks (docs/distributed.md), in
// rounds: first whole subtrees under one level, dealt out largest first to the least loaded rank
// (a subtree's work is the leaf triangles under it); then each level above them, its nodes dealt
// out the same way, once the level below is done. Every rank computes the same share.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/tiling/octree.h"

namespace lodforge {

struct OctreeShare {
  int splitLevel = 0;               // the subtrees' roots are the nodes of this level
  int rounds = 1;                   // the subtrees, then one round per level above them
  std::vector<int> owner;           // per node: the rank that builds it
  std::vector<int> round;           // per node: when (0: in its subtree; k: level split + k)
  std::vector<std::uint64_t> work;  // per rank: the leaf triangles under its subtrees
};

// The share of `nodes` (as planned: leaves first, children listed) over `ranks`;
// `leafTriangles` per node (0 above the leaves). The split is the highest level whose subtrees
// leave the least loaded rank at least (1 - tolerance) of the busiest one's work, else the best
// balanced level; never the leaves while a level above them exists (the leaves are only read,
// the simplification is above them).
OctreeShare shareOctree(const std::vector<OctreeNode>& nodes,
                        std::span<const std::uint64_t> leafTriangles, int ranks,
                        double tolerance = 0.05);

// The least loaded rank's subtree work over the busiest one's (1: perfectly even).
double shareBalance(const OctreeShare& share);

}  // namespace lodforge
