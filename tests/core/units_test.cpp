#include "lodforge/core/units.h"

#include <gtest/gtest.h>

namespace lodforge {
namespace {

TEST(Units, ByteSizesUseBinaryMultiples) {
  EXPECT_EQ(parseByteSize("2G"), 2ull << 30);
  EXPECT_EQ(parseByteSize("512M"), 512ull << 20);
  EXPECT_EQ(parseByteSize("1.5K"), 1536u);
  EXPECT_EQ(parseByteSize("2GiB"), 2ull << 30);
  EXPECT_EQ(parseByteSize("2gb"), 2ull << 30);
  EXPECT_EQ(parseByteSize("123"), 123u);
  EXPECT_EQ(parseByteSize(" 7k "), 7168u);
  EXPECT_EQ(parseByteSize("1T"), 1ull << 40);
}

TEST(Units, CountsUseDecimalMultiples) {
  EXPECT_EQ(parseCount("100M"), 100'000'000u);
  EXPECT_EQ(parseCount("10K"), 10'000u);
  EXPECT_EQ(parseCount("1G"), 1'000'000'000u);
  EXPECT_EQ(parseCount("2.5M"), 2'500'000u);
  EXPECT_EQ(parseCount("1000000"), 1'000'000u);
  // A count is whole: 1.5 threads or 2.5 points is refused, not rounded.
  for (const char* fraction : {"1.5", "0.5", "2.0005K"})
    EXPECT_FALSE(parseCount(fraction).has_value()) << fraction;
  EXPECT_EQ(parseByteSize("0.5K"), 512u);  // sizes are rounded to the byte
}

TEST(Units, RejectsWhatIsNotASize) {
  for (const char* bad : {"", "abc", "-1", "1X", "1KK", "G", "1e400", "nan", "1.2.3"}) {
    EXPECT_FALSE(parseByteSize(bad).has_value()) << bad;
    EXPECT_FALSE(parseCount(bad).has_value()) << bad;
  }
}

TEST(Units, FormatsForPeople) {
  EXPECT_EQ(formatBytes(17), "17 B");
  EXPECT_EQ(formatBytes(1536), "1.50 KiB");
  EXPECT_EQ(formatBytes(3ull << 30), "3.00 GiB");
  EXPECT_EQ(formatBytes(300ull << 20), "300 MiB");
  EXPECT_EQ(formatCount(0), "0");
  EXPECT_EQ(formatCount(999), "999");
  EXPECT_EQ(formatCount(1234567), "1,234,567");
}

}  // namespace
}  // namespace lodforge
