#include "lodforge/tiling/octree_share.h"

#include <algorithm>
#include <cassert>
#include <optional>

#include "lodforge/core/cluster.h"

namespace lodforge {
namespace {

// Leaf triangles under each node (children are listed before their parents).
std::vector<std::uint64_t> subtreeWork(const std::vector<OctreeNode>& nodes,
                                       std::span<const std::uint64_t> leafTriangles) {
  std::vector<std::uint64_t> work(leafTriangles.begin(), leafTriangles.end());
  for (std::size_t i = 0; i < nodes.size(); ++i)
    for (std::uint32_t c : nodes[i].children) {
      assert(c < i);
      work[i] += work[c];
    }
  return work;
}

// The nodes of `level` dealt out largest first to the least loaded rank (dealLargestFirst).
// Returns each rank's work.
std::vector<std::uint64_t> dealLevel(const std::vector<OctreeNode>& nodes,
                                     std::span<const std::uint64_t> work, int level, int ranks,
                                     std::vector<int>& owner) {
  std::vector<std::uint32_t> roots;
  std::vector<std::uint64_t> rootWork;
  for (std::uint32_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].level == level) {
      roots.push_back(i);
      rootWork.push_back(work[i]);
    }
  const std::vector<int> dealt = dealLargestFirst(rootWork, ranks);
  std::vector<std::uint64_t> load(static_cast<std::size_t>(ranks), 0);
  for (std::size_t k = 0; k < roots.size(); ++k) {
    owner[roots[k]] = dealt[k];
    load[static_cast<std::size_t>(dealt[k])] += rootWork[k];
  }
  return load;
}

// Whole subtrees under `split` (round 0), then each level above it in a round of its own.
OctreeShare shareAt(const std::vector<OctreeNode>& nodes, std::span<const std::uint64_t> work,
                    int split, int top, int ranks) {
  OctreeShare share{split,
                    top - split + 1,
                    std::vector<int>(nodes.size(), 0),
                    std::vector<int>(nodes.size(), 0),
                    {}};
  share.work = dealLevel(nodes, work, split, ranks, share.owner);
  // A subtree's nodes go with its root (children before parents: walk down from the roots).
  for (std::size_t i = nodes.size(); i-- > 0;)
    if (nodes[i].level <= split)
      for (std::uint32_t c : nodes[i].children) share.owner[c] = share.owner[i];
  for (int level = split + 1; level <= top; ++level) {
    (void)dealLevel(nodes, work, level, ranks, share.owner);
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (nodes[i].level == level) share.round[i] = level - split;
  }
  return share;
}

}  // namespace

double shareBalance(const OctreeShare& share) {
  const auto [least, most] = std::minmax_element(share.work.begin(), share.work.end());
  return *most == 0 ? 1.0 : static_cast<double>(*least) / static_cast<double>(*most);
}

OctreeShare shareOctree(const std::vector<OctreeNode>& nodes,
                        std::span<const std::uint64_t> leafTriangles, int ranks, double tolerance) {
  assert(ranks >= 1 && leafTriangles.size() == nodes.size());
  const std::vector<std::uint64_t> work = subtreeWork(nodes, leafTriangles);
  int top = 0;
  for (const OctreeNode& node : nodes) top = std::max(top, node.level);
  std::optional<OctreeShare> best;
  for (int level = top; level >= std::min(top, 1); --level) {
    OctreeShare share = shareAt(nodes, work, level, top, ranks);
    if (shareBalance(share) >= 1 - tolerance) return share;
    if (!best || shareBalance(share) > shareBalance(*best)) best = std::move(share);
  }
  return std::move(*best);
}

}  // namespace lodforge
