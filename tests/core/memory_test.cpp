#include "lodforge/core/memory.h"

#include <cstring>
#include <memory>

#include <gtest/gtest.h>

namespace lodforge {
namespace {

TEST(Rss, PeakGrowsWhenMemoryIsTouched) {
  const std::uint64_t before = peakRssBytes();
  EXPECT_GT(currentRssBytes(), 0u);
  EXPECT_GE(before, currentRssBytes() / 2);
  constexpr std::size_t kBytes = 64 << 20;
  auto block = std::make_unique<char[]>(kBytes);
  std::memset(block.get(), 1, kBytes);
  EXPECT_GE(peakRssBytes(), before + kBytes / 2);
  EXPECT_EQ(block[kBytes - 1], 1);
}

TEST(MemoryBudget, RefusesBeyondTheLimit) {
  MemoryBudget budget(1000);
  ASSERT_TRUE(budget.reserve(600, "a").ok());
  const Status refused = budget.reserve(500, "chunk buffer");
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.kind(), ErrorKind::kLimit);
  EXPECT_NE(refused.message().find("chunk buffer"), std::string::npos);
  budget.release(600);
  EXPECT_TRUE(budget.reserve(1000, "b").ok());
  MemoryBudget unlimited;
  EXPECT_TRUE(unlimited.reserve(1ull << 50, "huge").ok());
}

}  // namespace
}  // namespace lodforge
