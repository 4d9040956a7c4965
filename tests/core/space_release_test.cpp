#include "lodforge/core/space_release.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

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

// The unit SpaceRelease punches in for a file in `dir`: the larger of the page and the file
// system's block.
std::uint64_t holeUnit(const test::TempDir& dir) {
  struct stat info {};
  EXPECT_EQ(::stat(dir.file("").c_str(), &info), 0);
  return std::max<std::uint64_t>(static_cast<std::uint64_t>(info.st_blksize),
                                 static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE)));
}

// A punched range reads zeros over its whole pages only, and the file holds that much less; a
// removed file is gone; what is asked after finish() is done at once, and completes the pages
// it shares with earlier ranges.
TEST(SpaceRelease, PunchesWholePagesOnlyAndRemovesFiles) {
  test::TempDir dir;
  const std::uint64_t kPage = holeUnit(dir);
  const std::string bytes = pattern(12 * kPage + 100);
  test::writeFile(dir.file("work"), bytes);
  test::writeFile(dir.file("done"), pattern(3000));
  const std::uint64_t before = allocatedBytes(dir.file("work"));
  SpaceRelease release;
  // [1000, 1000 + 5 pages): the pages 1 to 4 are whole inside; bytes 0 to the first page's end
  // and from 5 pages on are another block's and must stay.
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
  // A range that completes page 5 with the first one's tail [5 pages, 5 pages + 1000) frees it
  // and page 6; page 7 waits for its last bytes.
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

// Through the thread: ranges smaller than a page, given one after another in a shuffled order
// (batched or not, as the thread takes them), free every page they cover together and nothing
// beyond them.
TEST(SpaceRelease, NeighbouringRangesFreeThePagesTheyCoverTogether) {
  test::TempDir dir;
  const std::uint64_t page = holeUnit(dir);
  const std::string bytes = pattern(20 * page);
  test::writeFile(dir.file("work"), bytes);
  const std::uint64_t before = allocatedBytes(dir.file("work"));
  // [2 pages + 7, 17 pages + 7) in pieces of a third of a page or so.
  const std::uint64_t begin = 2 * page + 7, end = 17 * page + 7;
  std::vector<ByteRange> pieces;
  for (std::uint64_t at = begin; at < end; at += page / 3 + 1)
    pieces.push_back({at, std::min(page / 3 + 1, end - at)});
  Random random(3);
  for (std::size_t i = pieces.size(); i > 1; --i)
    std::swap(pieces[i - 1], pieces[random.next() % i]);
  {
    SpaceRelease release;
    for (const ByteRange& r : pieces) release.punch(dir.file("work"), r.offset, r.length);
  }  // finished by its destructor
  const std::string after = test::readFile(dir.file("work"));
  EXPECT_EQ(after.substr(0, 3 * page), bytes.substr(0, 3 * page));  // page 2 is not whole
  EXPECT_EQ(after.substr(3 * page, 14 * page), std::string(14 * page, '\0'));
  EXPECT_EQ(after.substr(17 * page), bytes.substr(17 * page));
  EXPECT_EQ(allocatedBytes(dir.file("work")), before - 14 * page);
}

}  // namespace
}  // namespace lodforge
