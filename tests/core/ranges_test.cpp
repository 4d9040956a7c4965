#include "lodforge/core/ranges.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"

namespace lodforge {
namespace {

std::vector<bool> covered(const std::vector<ElementRange>& ranges, std::size_t size) {
  std::vector<bool> in(size, false);
  for (const ElementRange& r : ranges) std::fill(in.begin() + r.begin, in.begin() + r.end, true);
  return in;
}

TEST(Ranges, TouchingRangesMergeAndFarOnesStayApart) {
  std::vector<ElementRange> ranges = {{10, 12}, {0, 4}, {4, 6}, {11, 15}, {20, 21}};
  RangeScratch scratch;
  mergeRanges(ranges, 10, scratch);
  ASSERT_EQ(ranges.size(), 3u);
  EXPECT_EQ(ranges[0].begin, 0u);
  EXPECT_EQ(ranges[0].end, 6u);
  EXPECT_EQ(ranges[1].begin, 10u);
  EXPECT_EQ(ranges[1].end, 15u);
  EXPECT_EQ(ranges[2].begin, 20u);
  // Two at most: the smaller gap (6 -> 10, against 15 -> 20) closes first.
  mergeRanges(ranges, 2, scratch);
  ASSERT_EQ(ranges.size(), 2u);
  EXPECT_EQ(ranges[0].begin, 0u);
  EXPECT_EQ(ranges[0].end, 15u);
  EXPECT_EQ(ranges[1].begin, 20u);
  EXPECT_EQ(ranges[1].end, 21u);
}

// Random ranges: never more than asked, sorted with gaps between, every element still covered.
// Equal gaps (an assembly of equal parts): exactly enough of them close, the first ones.
TEST(Ranges, EqualGapsCloseOnlyAsManyAsNeeded) {
  std::vector<ElementRange> ranges;
  for (std::uint64_t k = 0; k < 100; ++k) ranges.push_back({10 * k, 10 * k + 5});
  RangeScratch scratch;
  mergeRanges(ranges, 60, scratch);
  ASSERT_EQ(ranges.size(), 60u);
  EXPECT_EQ(ranges[0].begin, 0u);
  EXPECT_EQ(ranges[0].end, 405u);  // the first 41 merged: the 40 first gaps closed
  EXPECT_EQ(ranges[1].begin, 410u);
  EXPECT_EQ(ranges[59].end, 995u);
}

TEST(Ranges, RandomRangesKeepEveryElementWithinTheCount) {
  Random random(5);
  RangeScratch scratch;
  for (int round = 0; round < 200; ++round) {
    constexpr std::size_t kSize = 2000;
    std::vector<ElementRange> ranges(random.below(60));
    for (ElementRange& r : ranges) {
      r.begin = random.below(kSize - 10);
      r.end = r.begin + 1 + random.below(10);
    }
    const std::vector<bool> before = covered(ranges, kSize);
    std::vector<ElementRange> touching = ranges;  // only touching ones merged
    mergeRanges(touching, ranges.size() + 1, scratch);
    const std::size_t most = 1 + random.below(20);
    mergeRanges(ranges, most, scratch);
    // Exactly as many as asked when there were more (each closed gap removes one).
    ASSERT_EQ(ranges.size(), std::min(most, touching.size()));
    for (std::size_t k = 1; k < ranges.size(); ++k) ASSERT_GT(ranges[k].begin, ranges[k - 1].end);
    const std::vector<bool> after = covered(ranges, kSize);
    for (std::size_t i = 0; i < kSize; ++i) ASSERT_TRUE(!before[i] || after[i]) << i;
    // Each range starts and ends on an element the input covered (no growth past the ends).
    for (const ElementRange& r : ranges) {
      ASSERT_TRUE(before[r.begin]);
      ASSERT_TRUE(before[r.end - 1]);
    }
  }
}

}  // namespace
}  // namespace lodforge
