// Per-block data reorganisation (points paper §4.1): top-down hierarchical clustering into a binary
// tree down to single points, a planar square fitted to every node with its error, and the cut of
// the tree by an error tolerance into Part I (dropped), Part II (kept in memory) and Part III (the
// block's segment file), Fig. 4.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/points/partition.h"

namespace lodforge {

// The paper's basic primitive (§4.2 "Data structures"), 44 bytes on disk: a planar square of
// `radius` at `position` (relative to the block's origin) facing `normal`, the number of input
// points it stands for, its fitting error and where its two children are (consecutive records).
struct ClusterNode {
  Vec3f position;
  Vec3f normal;
  Rgba8 color;
  float radius = 0;
  float error = 0;  // metres; never below a descendant's (so a cut is a cut)
  std::uint32_t pointCount = 0;
  std::uint32_t firstChild = kNoChild;  // children at firstChild and firstChild + 1
  static constexpr std::uint32_t kNoChild = ~0u;
  bool leaf() const { return firstChild == kNoChild; }
};
static_assert(sizeof(ClusterNode) == 44);

struct ClusterOptions {
  double alpha1 = 0.5, alpha2 = 0.5;  // weights of distance and normal difference (the paper's)
  int neighbours = 12;                // k: the fewest points in a normal's neighbourhood
  bool colors = true;  // nodes' mean colours (point packages draw them; tiles leave them 0)
};

// The clustering tree of one block, breadth-first with the root first; `points` is reordered.
// Without `hasNormals`, each point's normal is estimated (and written into `points`) by PCA over
// its cell: the smallest node of the tree with at least k points, turned to face +z (up, for
// aerial and terrestrial scans).
// Node error E = α1·mean|(p_i − c)·n| + α2·r·mean(1 − n_i·n): the paper's distance and normal
// terms, the second scaled by the square's radius so that E is a length (see docs/points.md).
// Leaves are single points whose radius is half the distance to their nearest neighbour.
// With `firstPoint`, each node's first point (its range in the reordered `points` starts
// there; a leaf's is its point). `ids`, if given (one per point), is reordered with the points.
std::vector<ClusterNode> clusterBlock(std::span<CloudPoint> points, Vec3d origin, bool hasNormals,
                                      const ClusterOptions& options = {},
                                      std::vector<std::uint32_t>* firstPoint = nullptr,
                                      std::span<std::uint32_t> ids = {});

// The cut of a tree at `tolerance` (Fig. 4): Part II is every node with error ≤ tolerance whose
// parent's error is above it (or the root); Part I, their ancestors, is dropped; Part III, their
// descendants, breadth-first. firstChild of Part II records points into Part III, and Part III's
// into itself.
struct LodCut {
  std::vector<ClusterNode> resident;  // Part II
  std::vector<ClusterNode> segment;   // Part III
  std::uint32_t dropped = 0;          // Part I
};
LodCut cutTree(std::span<const ClusterNode> tree, float tolerance);

// The smallest tolerance whose cut keeps at most `residentNodes` nodes in Part II.
float toleranceForResident(std::span<const ClusterNode> tree, std::size_t residentNodes);

}  // namespace lodforge
