#include "lodforge/tiling/octree_share.h"

#include <algorithm>
#include <map>
#include <numeric>

#include <gtest/gtest.h>

namespace lodforge {
namespace {

// An octree planned the way buildOctree plans it: the leaves, then 2x2x2 groups level by level
// up to one root; `leafTriangles` per node (0 above the leaves).
struct PlannedTree {
  std::vector<OctreeNode> nodes;
  std::vector<std::uint64_t> leafTriangles;
};

PlannedTree planTree(const std::map<ChunkCell, std::uint64_t>& leaves) {
  PlannedTree tree;
  std::vector<std::uint32_t> level;
  for (const auto& [cell, triangles] : leaves) {
    OctreeNode leaf;
    leaf.cell = cell;
    level.push_back(static_cast<std::uint32_t>(tree.nodes.size()));
    tree.nodes.push_back(leaf);
    tree.leafTriangles.push_back(triangles);
  }
  for (int depth = 1; level.size() > 1; ++depth) {
    std::map<ChunkCell, std::vector<std::uint32_t>> groups;
    for (std::uint32_t i : level) {
      const ChunkCell& c = tree.nodes[i].cell;
      groups[{c[0] >> 1, c[1] >> 1, c[2] >> 1}].push_back(i);
    }
    level.clear();
    for (auto& [cell, children] : groups) {
      OctreeNode parent;
      parent.level = depth;
      parent.cell = cell;
      parent.children = children;
      level.push_back(static_cast<std::uint32_t>(tree.nodes.size()));
      tree.nodes.push_back(parent);
      tree.leafTriangles.push_back(0);
    }
  }
  return tree;
}

// A scan-like sheet of side x side leaves; those with x and y below `corner` hold `dense`
// triangles, the others `sparse`.
PlannedTree sheet(int side, int corner, std::uint64_t dense, std::uint64_t sparse) {
  std::map<ChunkCell, std::uint64_t> leaves;
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) leaves[{x, y, 0}] = x < corner && y < corner ? dense : sparse;
  return planTree(leaves);
}

// What every share must be: whole subtrees under the split in round 0 (a node's children have
// its owner), each level above in a round of its own, every owner a rank, and the ranks'
// subtree work adding up to all leaf triangles.
void expectRounds(const PlannedTree& tree, const OctreeShare& share, int ranks) {
  ASSERT_EQ(share.owner.size(), tree.nodes.size());
  ASSERT_EQ(share.round.size(), tree.nodes.size());
  ASSERT_EQ(share.work.size(), static_cast<std::size_t>(ranks));
  int top = 0;
  for (const OctreeNode& node : tree.nodes) top = std::max(top, node.level);
  EXPECT_EQ(share.rounds, top - share.splitLevel + 1);
  std::vector<std::uint64_t> work(static_cast<std::size_t>(ranks), 0);
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const OctreeNode& node = tree.nodes[i];
    ASSERT_GE(share.owner[i], 0) << "node " << i;
    ASSERT_LT(share.owner[i], ranks) << "node " << i;
    EXPECT_EQ(share.round[i], std::max(0, node.level - share.splitLevel)) << "node " << i;
    if (node.level <= share.splitLevel) {
      for (std::uint32_t c : node.children) EXPECT_EQ(share.owner[c], share.owner[i]) << i;
    }
    if (node.level == 0) work[static_cast<std::size_t>(share.owner[i])] += tree.leafTriangles[i];
  }
  EXPECT_EQ(work, share.work);
  EXPECT_EQ(
      std::accumulate(work.begin(), work.end(), std::uint64_t{0}),
      std::accumulate(tree.leafTriangles.begin(), tree.leafTriangles.end(), std::uint64_t{0}));
}

// How many nodes of `level` each rank builds.
std::vector<int> nodesOfLevel(const PlannedTree& tree, const OctreeShare& share, int level,
                              int ranks) {
  std::vector<int> count(static_cast<std::size_t>(ranks), 0);
  for (std::size_t i = 0; i < tree.nodes.size(); ++i)
    if (tree.nodes[i].level == level) ++count[static_cast<std::size_t>(share.owner[i])];
  return count;
}

TEST(OctreeShare, AnEvenScanIsSharedEvenlyAndTheLevelsAboveToo) {
  const PlannedTree tree = sheet(16, 0, 0, 50'000);
  for (int ranks : {1, 2, 3, 4}) {
    const OctreeShare share = shareOctree(tree.nodes, tree.leafTriangles, ranks);
    expectRounds(tree, share, ranks);
    EXPECT_GE(shareBalance(share), 0.95) << ranks << " ranks";
    // The level above the subtrees has more nodes than ranks: none is left out of it.
    const std::vector<int> above = nodesOfLevel(tree, share, share.splitLevel + 1, ranks);
    if (ranks > 1 && share.splitLevel + 1 < 4) {
      EXPECT_EQ(std::count(above.begin(), above.end(), 0), 0) << ranks << " ranks";
    }
  }
  // 16 x 16 leaves: 2 x 2 subtrees at level 3 balance 2 and 4 ranks exactly; 3 ranks go lower.
  EXPECT_EQ(shareOctree(tree.nodes, tree.leafTriangles, 2).splitLevel, 3);
  EXPECT_EQ(shareOctree(tree.nodes, tree.leafTriangles, 4).splitLevel, 3);
  EXPECT_LT(shareOctree(tree.nodes, tree.leafTriangles, 3).splitLevel, 3);
  EXPECT_EQ(shareOctree(tree.nodes, tree.leafTriangles, 1).splitLevel, 4) << "one rank: the root";
  EXPECT_EQ(shareOctree(tree.nodes, tree.leafTriangles, 1).rounds, 1);
}

TEST(OctreeShare, ADenseCornerIsBalancedWithinTwentyPercentOfTheBusiestRank) {
  // A quarter of a sheet holds 20 times the triangles of the rest (73 % of all of them).
  const PlannedTree tree = sheet(16, 8, 1'000'000, 50'000);
  const PlannedTree even = sheet(16, 0, 0, 50'000);
  for (int ranks : {2, 3, 4}) {
    const OctreeShare share = shareOctree(tree.nodes, tree.leafTriangles, ranks);
    expectRounds(tree, share, ranks);
    EXPECT_GE(shareBalance(share), 0.8) << ranks << " ranks, split at level " << share.splitLevel;
    // At the even sheet's split the dense quarter's subtrees would be too big to balance: the
    // share went lower (3 ranks are at the lowest level already for the even sheet).
    const OctreeShare evenShare = shareOctree(even.nodes, even.leafTriangles, ranks);
    if (evenShare.splitLevel > 1) {
      EXPECT_LT(share.splitLevel, evenShare.splitLevel) << ranks << " ranks";
    } else {
      EXPECT_EQ(share.splitLevel, 1) << ranks << " ranks";
    }
  }
}

TEST(OctreeShare, TheBalanceMeasureSeesAnUnevenShare) {
  // One subtree of four holding most of the work cannot be balanced at its level: a planted
  // uneven share must read as one.
  OctreeShare share;
  share.work = {700, 100, 100};
  EXPECT_NEAR(shareBalance(share), 100.0 / 700.0, 1e-12);
  share.work = {0, 0};
  EXPECT_EQ(shareBalance(share), 1.0) << "no work is even";
}

TEST(OctreeShare, MoreRanksThanChunksLeaveSomeRanksIdle) {
  const PlannedTree tree = planTree({{{0, 0, 0}, 500}, {{1, 0, 0}, 700}});
  const OctreeShare share = shareOctree(tree.nodes, tree.leafTriangles, 4);
  expectRounds(tree, share, 4);
  EXPECT_EQ(share.splitLevel, 1) << "never the leaves while a level above exists";
  EXPECT_EQ(std::count(share.work.begin(), share.work.end(), 0), 3);
  // A single chunk: the leaf is the whole tree.
  const PlannedTree one = planTree({{{3, 4, 5}, 10}});
  const OctreeShare single = shareOctree(one.nodes, one.leafTriangles, 3);
  expectRounds(one, single, 3);
  EXPECT_EQ(single.splitLevel, 0);
}

}  // namespace
}  // namespace lodforge
