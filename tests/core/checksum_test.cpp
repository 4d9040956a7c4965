#include "lodforge/core/checksum.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "test_support.h"

namespace lodforge {
namespace {

TEST(Checksum, KnownValueOfTheEmptyInput) {
  // XXH3-64 of no bytes, from the xxHash specification's test vectors.
  EXPECT_EQ(checksum64({}), 0x2D06800538D394C2ull);
}

TEST(Checksum, IncrementalEqualsOneShotForAnySplit) {
  Random random(9);
  std::vector<std::byte> data(100'000);
  for (std::byte& b : data) b = std::byte(random.below(256));
  const std::uint64_t whole = checksum64(data);
  for (int trial = 0; trial < 20; ++trial) {
    Checksum64 incremental;
    std::size_t at = 0;
    while (at < data.size()) {
      const std::size_t n = std::min<std::size_t>(data.size() - at, random.below(5000) + 1);
      incremental.update(std::span(data).subspan(at, n));
      at += n;
    }
    EXPECT_EQ(incremental.digest(), whole);
  }
  data[500] ^= std::byte{1};
  EXPECT_NE(checksum64(data), whole);
}

}  // namespace
}  // namespace lodforge
