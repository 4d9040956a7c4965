#include "lodforge/tiles/point_resume.h"

#include <bit>
#include <cmath>
#include <filesystem>
#include <limits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/random.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

// Doubles compared by their bits: the state must give back exactly what it was given (a −0
// bound, say, is not +0).
bool sameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

bool sameBits(const Vec3d& a, const Vec3d& b) {
  return sameBits(a.x, b.x) && sameBits(a.y, b.y) && sameBits(a.z, b.z);
}

bool sameBits(const Aabbd& a, const Aabbd& b) {
  return sameBits(a.min, b.min) && sameBits(a.max, b.max);
}

// A split of random values (fixed seed), with a −0 corner and a truncation.
SplitState randomSplit() {
  Random random(7);
  const auto value = [&] { return (random.uniform() - 0.5) * 1e7 / 3.0; };
  SplitState state;
  state.count = 1'234'567;
  state.bounds.min = {-0.0, value(), value()};
  state.bounds.max = {value(), value(), -0.0};
  state.sum = {value(), value(), value()};
  state.truncation = "p.ply: cut short at byte 99";
  for (const char* name : {"b00", "b01", "b1"}) {
    PartitionNode node;
    node.name = name;
    node.first = random.below(1000);
    node.count = random.below(1000) + 1;
    node.bounds.min = {value(), value(), value()};
    node.bounds.max = {value(), value(), value()};
    node.sum = {value(), value(), value()};
    state.nodes.push_back(node);
  }
  return state;
}

TEST(PointResume, TheSplitStateComesBackBitForBitOnlyForTheSameIdentity) {
  test::TempDir dir;
  const std::string input = dir.file("p.xyz");
  test::writeFile(input, "0 0 0\n1 1 1\n");
  PointTilesOptions options;
  const nlohmann::json identity = pointRunIdentity(input, options);
  const SplitState state = randomSplit();
  test::writeFile(dir.file("b.points"), std::string(640, 'x'));
  ASSERT_TRUE(saveSplitState(dir.path().string(), identity, state).ok());
  EXPECT_TRUE(pointWorkKept(dir.path().string()));

  const std::optional<SplitState> back = loadSplitState(dir.path().string(), identity);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->count, state.count);
  EXPECT_TRUE(sameBits(back->bounds, state.bounds));
  EXPECT_TRUE(sameBits(back->sum, state.sum));
  EXPECT_EQ(back->truncation, state.truncation);
  ASSERT_EQ(back->nodes.size(), state.nodes.size());
  for (std::size_t i = 0; i < state.nodes.size(); ++i) {
    EXPECT_EQ(back->nodes[i].name, state.nodes[i].name);
    EXPECT_EQ(back->nodes[i].first, state.nodes[i].first);
    EXPECT_EQ(back->nodes[i].count, state.nodes[i].count);
    EXPECT_TRUE(sameBits(back->nodes[i].bounds, state.nodes[i].bounds));
    EXPECT_TRUE(sameBits(back->nodes[i].sum, state.nodes[i].sum));
  }

  // Work files cut short or gone since: start over.
  test::writeFile(dir.file("b.points"), std::string(639, 'x'));
  EXPECT_FALSE(loadSplitState(dir.path().string(), identity));
  fs::remove(dir.file("b.points"));
  EXPECT_FALSE(loadSplitState(dir.path().string(), identity));
  test::writeFile(dir.file("b.points"), std::string(640, 'y'));
  EXPECT_TRUE(loadSplitState(dir.path().string(), identity));

  // Any option that changes the output, or another input, is another run.
  PointTilesOptions other = options;
  other.tilePoints += 1;
  EXPECT_FALSE(loadSplitState(dir.path().string(), pointRunIdentity(input, other)));
  other = options;
  other.attributes = 0;
  EXPECT_FALSE(loadSplitState(dir.path().string(), pointRunIdentity(input, other)));
  test::writeFile(input, "0 0 0\n1 1 2\n3 3 3\n");
  EXPECT_FALSE(loadSplitState(dir.path().string(), pointRunIdentity(input, options)));
  // A damaged state is no state (split again), not an error.
  test::writeFile(dir.file("state.json"), "{\"identity\":");
  EXPECT_FALSE(loadSplitState(dir.path().string(), identity));
}

TEST(PointResume, ANodeIsDoneOnlyOnceItsRecordsAreInPlace) {
  test::TempDir dir;
  const std::string work = dir.path().string();
  fs::create_directories(dir.file("nodes"));
  InputRead read;
  read.count = 10;
  read.layout = PointRecordLayout::of(PointCloudInfo{}, false, RecordNormals::kInput);
  const std::vector<PartitionNode> nodes = {{"b0", 0, 4, {}, {}}, {"b1", 4, 6, {}, {}}};
  PointBlock block;
  block.name = "b0";
  block.count = 4;
  block.bounds.min = {-0.0, 1, 2};
  block.bounds.max = {3, 4, 5};
  block.centroid = {1.5, 2.5, 3.5};
  ASSERT_TRUE(
      writeRankedNode(work, "b0", "scratch-0", std::vector<RankedBlock>{{block, 2.5f, 0.25f}})
          .ok());
  // Staged (its records may not be in place yet) is not done.
  EXPECT_EQ(rankedNodesDone(work, nodes), (std::vector<bool>{false, false}));
  ASSERT_TRUE(markNodeDone(work, "b0").ok());
  EXPECT_EQ(rankedNodesDone(work, nodes), (std::vector<bool>{true, false}));
  EXPECT_EQ(nodesToRank(work, nodes).size(), 1u);
  EXPECT_EQ(nodesToRank(work, nodes)[0].name, "b1");

  // A summary gives its blocks back as written; a missing one is an error, not a hole.
  Result<std::vector<RankedBlock>> back =
      readRankedNodes(work, std::span(nodes).first(1), dir.file("b.points"), read.layout);
  ASSERT_TRUE(back.ok());
  ASSERT_EQ(back->size(), 1u);
  EXPECT_EQ((*back)[0].block.name, "b0");
  EXPECT_EQ((*back)[0].block.count, 4u);
  EXPECT_TRUE(sameBits((*back)[0].block.bounds, block.bounds));
  EXPECT_TRUE(sameBits((*back)[0].block.centroid, block.centroid));
  EXPECT_EQ((*back)[0].rootError, 2.5f);
  EXPECT_EQ((*back)[0].leastError, 0.25f);
  EXPECT_FALSE(readRankedNodes(work, nodes, dir.file("b.points"), read.layout).ok());
}

TEST(PointResume, ThePlanComesBackAsWritten) {
  test::TempDir dir;
  const std::string work = dir.path().string();
  Result<std::optional<PointPlan>> none = readPointPlan(work);
  ASSERT_TRUE(none.ok());
  EXPECT_FALSE(none->has_value());
  BlockTiles tiles;
  tiles.name = "b01";
  tiles.first = 77;
  tiles.counts = {1, 5, 30};
  tiles.bounds.min = {-0.0, -1, -2};
  tiles.bounds.max = {1.0 / 3.0, 2, 3};
  tiles.rootError = std::nextafter(0.1f, 1.0f);
  PointBlock block;
  block.count = 36;
  const std::vector<float> taus = {0.5f, std::nextafter(0.25f, 0.0f), 0.0f};
  ASSERT_TRUE(writePointPlan(work, taus, std::vector{tiles}, std::vector{block}).ok());
  Result<std::optional<PointPlan>> plan = readPointPlan(work);
  ASSERT_TRUE(plan.ok() && plan->has_value());
  EXPECT_EQ((*plan)->taus, taus);
  ASSERT_EQ((*plan)->blocks.size(), 1u);
  const BlockTiles& b = (*plan)->blocks[0];
  EXPECT_EQ(b.name, "b01");
  EXPECT_EQ(b.first, 77u);
  EXPECT_EQ(b.counts, tiles.counts);
  EXPECT_TRUE(sameBits(b.bounds, tiles.bounds));
  EXPECT_EQ(b.rootError, tiles.rootError);
  EXPECT_EQ((*plan)->partition[0].count, 36u);
  // A damaged plan is an error: the ranking it stands for has removed what it came from.
  test::writeFile(dir.file("plan.json"), "{\"taus\":[1]}");
  EXPECT_FALSE(readPointPlan(work).ok());
}

}  // namespace
}  // namespace lodforge
