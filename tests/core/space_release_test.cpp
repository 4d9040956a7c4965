#include "lodforge/core/space_release.h"

#include <sys/stat.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "test_support.h"

namespace lodforge {
namespace {

// The blocks found are whole, inside the range, and every whole block of the range is among them.
TEST(SpaceRelease, WholeBlocksInsideAreExactlyTheBlocksTheRangeCovers) {
  Random random(7);
  for (int trial = 0; trial < 10000; ++trial) {
    const std::uint64_t block = std::uint64_t{1} << random.next() % 14;
    const std::uint64_t offset = random.next() % (1 << 16), length = random.next() % (1 << 16);
    const ByteRange r = wholeBlocksInside(offset, length, block);
    std::uint64_t whole = 0;  // counted one block at a time
    for (std::uint64_t b = offset / block; b * block < offset + length; ++b)
      whole += b * block >= offset && (b + 1) * block <= offset + length ? 1 : 0;
    ASSERT_EQ(r.length, whole * block) << offset << " " << length << " " << block;
    if (r.length == 0) continue;
    EXPECT_EQ(r.offset % block, 0u);
    EXPECT_GE(r.offset, offset);
    EXPECT_LE(r.offset + r.length, offset + length);
  }
}

std::string pattern(std::size_t n) {
  std::string bytes(n, '\0');
  for (std::size_t i = 0; i < n; ++i) bytes[i] = static_cast<char>('a' + i % 23);
  return bytes;
}

std::uint64_t allocatedBytes(const std::string& path) {
  struct stat info {};
  EXPECT_EQ(::stat(path.c_str(), &info), 0);
  return static_cast<std::uint64_t>(info.st_blocks) * 512;
}

// A punched range reads zeros over its whole pages only, and the file holds that much less; a
// removed file is gone; what is asked after finish() is done at once.
TEST(SpaceRelease, PunchesWholePagesOnlyAndRemovesFiles) {
  test::TempDir dir;
  constexpr std::uint64_t kPage = 4096;
  const std::string bytes = pattern(12 * kPage + 100);
  test::writeFile(dir.file("work"), bytes);
  test::writeFile(dir.file("done"), pattern(3000));
  const std::uint64_t before = allocatedBytes(dir.file("work"));
  SpaceRelease release;
  // [1000, 1000 + 5 pages): the pages 1 to 4 are whole inside; bytes 0–4095 and from 5 pages on
  // are another block's and must stay.
  release.punch(dir.file("work"), 1000, 5 * kPage);
  release.remove(dir.file("done"));
  release.finish();
  std::string after = test::readFile(dir.file("work"));
  ASSERT_EQ(after.size(), bytes.size());
  EXPECT_EQ(after.substr(0, kPage), bytes.substr(0, kPage));
  EXPECT_EQ(after.substr(kPage, 4 * kPage), std::string(4 * kPage, '\0'));
  EXPECT_EQ(after.substr(5 * kPage), bytes.substr(5 * kPage));
  EXPECT_EQ(allocatedBytes(dir.file("work")), before - 4 * kPage);
  EXPECT_FALSE(std::filesystem::exists(dir.file("done")));
  EXPECT_EQ(release.bytesReleased(), 4 * kPage + 3000);
  // After finish(), on this thread: a range that completes page 5 with the first one's tail
  // [5 pages, 5 pages + 1000) frees it and page 6; page 7 waits for its last bytes.
  release.punch(dir.file("work"), 5 * kPage + 1000, 2 * kPage + 100);
  after = test::readFile(dir.file("work"));
  EXPECT_EQ(after.substr(5 * kPage, 2 * kPage), std::string(2 * kPage, '\0'));
  EXPECT_EQ(after.substr(7 * kPage), bytes.substr(7 * kPage));
  EXPECT_EQ(release.bytesReleased(), 6 * kPage + 3000);
  release.punch(dir.file("work"), 7 * kPage + 100, kPage);  // completes page 7
  after = test::readFile(dir.file("work"));
  EXPECT_EQ(after.substr(7 * kPage, kPage), std::string(kPage, '\0'));
  EXPECT_EQ(after.substr(8 * kPage), bytes.substr(8 * kPage));
  EXPECT_EQ(allocatedBytes(dir.file("work")), before - 7 * kPage);
}

}  // namespace
}  // namespace lodforge
