#include "lodforge/core/file.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

namespace lodforge {
namespace {

TEST(ByteSource, ReadsLinesAcrossBufferBoundariesFromFileAndMemory) {
  test::TempDir dir;
  // Lines long enough that several straddle the 1 MiB read buffer, with CRLF and a last line
  // without newline.
  std::string text;
  for (int i = 0; i < 3000; ++i)
    text += std::string(1000 + i % 7, char('a' + i % 26)) + (i % 2 ? "\r\n" : "\n");
  text += "last";
  test::writeFile(dir.file("lines.txt"), text);
  Result<ByteSource> file = ByteSource::openFile(dir.file("lines.txt"));
  ASSERT_TRUE(file.ok());
  ByteSource memory = ByteSource::fromMemory(test::bytesOf(text), "memory");
  for (ByteSource* source : {&file.value(), &memory}) {
    std::string line;
    for (int i = 0; i < 3000; ++i) {
      ASSERT_TRUE(source->readLine(line));
      ASSERT_EQ(line, std::string(1000 + i % 7, char('a' + i % 26))) << i;
    }
    ASSERT_TRUE(source->readLine(line));
    EXPECT_EQ(line, "last");
    EXPECT_FALSE(source->readLine(line));
    EXPECT_EQ(source->offset(), text.size());
  }
}

TEST(ByteSource, ReadSkipAndOffsets) {
  test::TempDir dir;
  std::string data(3 << 20, '\0');
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = char(i % 251);
  test::writeFile(dir.file("data.bin"), data);
  Result<ByteSource> source = ByteSource::openFile(dir.file("data.bin"));
  ASSERT_TRUE(source.ok());
  EXPECT_EQ(source->size(), data.size());
  char chunk[10];
  ASSERT_TRUE(source->read(chunk, 10));
  EXPECT_EQ(std::string(chunk, 10), data.substr(0, 10));
  ASSERT_TRUE(source->skip(2'000'000));  // past the buffer: seeks
  EXPECT_EQ(source->offset(), 2'000'010u);
  ASSERT_TRUE(source->read(chunk, 10));
  EXPECT_EQ(std::string(chunk, 10), data.substr(2'000'010, 10));
  EXPECT_FALSE(source->skip(data.size()));
  EXPECT_EQ(source->ensure(5u << 20),
            data.size() - 2'000'020);  // grows the buffer, stops at the end
  ASSERT_TRUE(source->skip(source->remaining() - 5));
  EXPECT_FALSE(source->read(chunk, 10));  // only 5 left: nothing consumed
  EXPECT_EQ(source->remaining(), 5u);
}

TEST(ByteSource, ReadsLargerThanItsBufferWithoutHoldingThemTwice) {
  test::TempDir dir;
  std::string data(5 << 20, '\0');
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = char((i * 7) % 253);
  test::writeFile(dir.file("data.bin"), data);
  Result<ByteSource> source = ByteSource::openFile(dir.file("data.bin"));
  ASSERT_TRUE(source.ok());
  std::string small(100, '\0'), big(3 << 20, '\0');
  ASSERT_TRUE(source->read(small.data(), small.size()));  // fills the buffer
  ASSERT_TRUE(source->read(big.data(), big.size()));      // the buffered rest, then direct
  EXPECT_EQ(big, data.substr(100, big.size()));
  EXPECT_EQ(source->offset(), 100u + big.size());
  ASSERT_TRUE(source->read(small.data(), small.size()));  // buffered reads go on from there
  EXPECT_EQ(small, data.substr(100 + big.size(), 100));
  std::string rest(source->remaining() + 1, '\0');
  EXPECT_FALSE(source->read(rest.data(), rest.size()));  // past the end: nothing consumed
  EXPECT_EQ(source->offset(), 200u + big.size());
  rest.pop_back();
  ASSERT_TRUE(source->read(rest.data(), rest.size()));
  EXPECT_EQ(rest, data.substr(200 + big.size()));
  EXPECT_EQ(source->remaining(), 0u);
}

TEST(ByteSource, RefusesOverlongLinesAndMissingFiles) {
  const std::string text(5000, 'x');
  ByteSource memory = ByteSource::fromMemory(test::bytesOf(text), "long.txt");
  std::string line;
  try {
    memory.readLine(line, 100);
    FAIL() << "expected an error";
  } catch (const ErrorException& e) {
    EXPECT_EQ(e.error.kind, ErrorKind::kBadInput);
    EXPECT_NE(e.error.message.find("long.txt"), std::string::npos);
  }
  Result<ByteSource> missing = ByteSource::openFile("/nonexistent/file.ply");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().kind, ErrorKind::kIo);
  EXPECT_NE(missing.error().message.find("/nonexistent/file.ply"), std::string::npos);
}

TEST(OutputFile, AppearsOnlyOnCommit) {
  test::TempDir dir;
  const std::string path = dir.file("out.bin");
  {
    Result<OutputFile> out = OutputFile::create(path);
    ASSERT_TRUE(out.ok());
    ASSERT_TRUE(out->write("hello ", 6).ok());
    EXPECT_FALSE(std::filesystem::exists(path));
    ASSERT_TRUE(out->commit().ok());
  }
  EXPECT_EQ(test::readFile(path), "hello ");
  {
    Result<OutputFile> out = OutputFile::create(dir.file("abandoned.bin"));
    ASSERT_TRUE(out.ok());
    ASSERT_TRUE(out->write("partial", 7).ok());
  }  // destroyed without commit: the temporary disappears
  EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{"out.bin"});
}

TEST(OutputFile, PositionalWritesAndAppendedFiles) {
  test::TempDir dir;
  test::writeFile(dir.file("tail.bin"), "0123456789");
  Result<OutputFile> out = OutputFile::create(dir.file("out.bin"));
  ASSERT_TRUE(out.ok());
  ASSERT_TRUE(out->writeAt(4, "WXYZ", 4).ok());
  ASSERT_TRUE(out->writeAt(0, "abcd", 4).ok());
  ASSERT_TRUE(out->writeAt(8, "", 0).ok());
  ASSERT_TRUE(out->commit().ok());
  EXPECT_EQ(test::readFile(dir.file("out.bin")), "abcdWXYZ");

  Result<OutputFile> joined = OutputFile::create(dir.file("joined.bin"));
  ASSERT_TRUE(joined.ok());
  ASSERT_TRUE(joined->write("head:", 5).ok());
  ASSERT_TRUE(joined->appendFileContents(dir.file("tail.bin"), 6).ok());
  ASSERT_TRUE(joined->write(":end", 4).ok());
  EXPECT_EQ(joined->bytesWritten(), 15u);
  ASSERT_TRUE(joined->commit().ok());
  EXPECT_EQ(test::readFile(dir.file("joined.bin")), "head:012345:end");
}

TEST(OutputFile, WritesLargerThanTheBufferGoStraightToTheFileInOrder) {
  test::TempDir dir;
  Result<OutputFile> out = OutputFile::create(dir.file("out.bin"), 4096);
  ASSERT_TRUE(out.ok());
  std::string big(10'000, 'b'), expected = "head";
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>('a' + i % 26);
  ASSERT_TRUE(out->write("head", 4).ok());               // buffered
  ASSERT_TRUE(out->write(big.data(), big.size()).ok());  // past the buffer, after "head"
  ASSERT_TRUE(out->write("mid", 3).ok());
  ASSERT_TRUE(out->write(big.data(), 4096).ok());  // exactly the buffer's size
  ASSERT_TRUE(out->write("end", 3).ok());
  expected += big + "mid" + big.substr(0, 4096) + "end";
  EXPECT_EQ(out->bytesWritten(), expected.size());
  ASSERT_TRUE(out->commit().ok());
  EXPECT_EQ(test::readFile(dir.file("out.bin")), expected);
}

TEST(OutputFile, FailsCleanlyWhereItCannotWrite) {
  Result<OutputFile> out = OutputFile::create("/nonexistent-dir/out.glb");
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.error().kind, ErrorKind::kIo);
  EXPECT_NE(out.error().message.find("/nonexistent-dir/out.glb"), std::string::npos);
}

// The I/O buffer keeps the bytes below its size when it grows; a move takes them and leaves the
// source empty.
TEST(IoBuffer, KeepsItsBytesThroughResizesAndMoves) {
  IoBuffer buffer;
  EXPECT_EQ(buffer.size(), 0u);
  buffer.resize(3);
  std::memcpy(buffer.data(), "abc", 3);
  buffer.resize(1 << 20);
  EXPECT_EQ(std::memcmp(buffer.data(), "abc", 3), 0);
  buffer.resize(2);
  EXPECT_EQ(buffer.size(), 2u);
  buffer.resize(1 << 21);  // past its memory: a new block, the two bytes copied
  EXPECT_EQ(std::memcmp(buffer.data(), "ab", 2), 0);
  buffer.data()[2] = std::byte{'c'};
  buffer.resize(3);
  IoBuffer taken(std::move(buffer));
  EXPECT_EQ(taken.size(), 3u);
  EXPECT_EQ(std::memcmp(taken.data(), "abc", 3), 0);
  EXPECT_EQ(buffer.size(), 0u);  // NOLINT(bugprone-use-after-move): what a move leaves
  buffer = std::move(taken);
  EXPECT_EQ(std::memcmp(buffer.data(), "abc", 3), 0);
}

// A file of records read back block by block: every record once, in order, whatever the block;
// a file smaller than the block is read in one block of its own size (at least one record).
TEST(FileBlocks, EveryRecordOnceInOrderAndNoBlockBiggerThanTheFile) {
  test::TempDir dir;
  std::vector<std::uint32_t> records(1000);
  for (std::uint32_t i = 0; i < records.size(); ++i) records[i] = i * 7 + 1;
  {
    std::ofstream out(dir.file("r.bin"), std::ios::binary);
    out.write(reinterpret_cast<const char*>(records.data()), 4 * records.size());
    std::ofstream(dir.file("empty.bin"), std::ios::binary);
  }
  for (const std::size_t block : {1, 7, 1000, 1 << 20}) {
    std::vector<std::uint32_t> back;
    std::size_t largest = 0;
    ASSERT_TRUE(forEachFileBlock<std::uint32_t>(dir.file("r.bin"), block,
                                                [&](std::span<const std::uint32_t> some) {
                                                  largest = std::max(largest, some.size());
                                                  back.insert(back.end(), some.begin(), some.end());
                                                  return Status{};
                                                })
                    .ok());
    EXPECT_EQ(back, records) << block;
    EXPECT_EQ(largest, std::min<std::size_t>(block, records.size())) << block;
  }
  const std::string r = dir.file("r.bin");
  EXPECT_EQ(blockForFile(r, 1 << 20, 4), 1000u);
  EXPECT_EQ(blockForFile(r, 10, 4), 10u);
  EXPECT_EQ(blockForFile(r, 1 << 20, 3000), 1u);  // one record's room, even past the end
  EXPECT_EQ(blockForFile(dir.file("empty.bin"), 1 << 20, 4), 1u);
}

TEST(MappedFile, SeesTheFileContents) {
  test::TempDir dir;
  test::writeFile(dir.file("m.bin"), "mapped bytes");
  Result<MappedFile> mapped = MappedFile::open(dir.file("m.bin"));
  ASSERT_TRUE(mapped.ok());
  const auto bytes = mapped->bytes();
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()), "mapped bytes");
  test::writeFile(dir.file("empty.bin"), "");
  Result<MappedFile> empty = MappedFile::open(dir.file("empty.bin"));
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->bytes().empty());
}

TEST(Paths, ExtensionsAreLowerCase) {
  EXPECT_EQ(fileExtension("a/b/Model.GLB"), "glb");
  EXPECT_EQ(fileExtension("scan.ply"), "ply");
  EXPECT_EQ(fileExtension("noext"), "");
  EXPECT_NE(temporaryPathFor("x.ply"), temporaryPathFor("x.ply"));
}

}  // namespace
}  // namespace lodforge
