// LAZ decoding: the real LAZ and COPC files in ../shared/data decode to exactly the records of
// their LAS twins.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "lodforge/io/points/las_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

// The records of `path` in batches of `batch`; only points [first, first + count) when given (a
// slice through restrictTo, what one rank of a job reads).
std::vector<std::byte> allRecords(
    const std::string& path, std::size_t batch = 1 << 16,
    std::optional<std::pair<std::uint64_t, std::uint64_t>> slice = std::nullopt) {
  Result<LasReader> reader = LasReader::open(path, batch);
  EXPECT_TRUE(reader.ok()) << reader.status().message();
  std::vector<std::byte> all, records;
  if (!reader.ok()) return all;
  if (slice) {
    const Status restricted = reader->restrictTo(slice->first, slice->second);
    EXPECT_TRUE(restricted.ok()) << restricted.message();
  }
  while (true) {
    Result<bool> more = reader->nextRecords(records);
    EXPECT_TRUE(more.ok()) << more.status().message();
    if (!more.ok() || !*more) break;
    all.insert(all.end(), records.begin(), records.end());
  }
  return all;
}

std::size_t firstDifference(const std::vector<std::byte>& a, const std::vector<std::byte>& b) {
  return static_cast<std::size_t>(std::mismatch(a.begin(), a.end(), b.begin(), b.end()).first -
                                  a.begin());
}

TEST(Laz, PointwiseChunkedVersion2DecodesToTheLasRecords) {
  const auto laz = allRecords(test::dataPath("points/autzen_trim.laz"));
  const auto las = allRecords(test::dataPath("points/autzen_trim.las"));
  ASSERT_EQ(las.size(), 110000u * 34);
  ASSERT_EQ(laz.size(), las.size());
  EXPECT_EQ(firstDifference(laz, las), las.size()) << "record " << firstDifference(laz, las) / 34;
}

// A slice of a LAZ file is decoded from the chunk that holds its first point (autzen_trim.laz:
// chunks of 50,000, 50,000 and 10,000 points; the COPC file: layered chunks) and is the whole
// file's records there: at a chunk's start, inside one, across two, in the last, at the end.
TEST(Laz, ASliceIsTheWholeFilesRecordsThere) {
  for (const char* name : {"points/autzen_trim.laz", "points/1.2-with-color.copc.laz"}) {
    const std::string path = test::dataPath(name);
    const std::vector<std::byte> whole = allRecords(path);
    Result<LasReader> probe = LasReader::open(path, 1);
    ASSERT_TRUE(probe.ok());
    const std::uint64_t points = probe->header().pointCount;
    const std::size_t length = probe->header().recordLength;
    ASSERT_EQ(whole.size(), points * length);
    for (const auto& [first, count] :
         std::vector<std::pair<std::uint64_t, std::uint64_t>>{{0, 1},
                                                              {points / 2, 7},
                                                              {49'990, 30},
                                                              {12'345, 70'000},
                                                              {points - 5, 100},
                                                              {points, 3}}) {
      SCOPED_TRACE(fmt::format("{} [{}, +{})", name, first, count));
      const std::uint64_t end = std::min(points, first + count);
      const std::vector<std::byte> slice = allRecords(path, 1000, std::pair{first, count});
      ASSERT_EQ(slice.size(), (end - std::min(first, end)) * length);
      EXPECT_TRUE(std::equal(slice.begin(), slice.end(),
                             whole.begin() + static_cast<std::ptrdiff_t>(first * length)));
    }
  }
}

TEST(Laz, PointwiseVersion1DecodesToTheLasRecords) {
  const auto laz = allRecords(test::dataPath("points/simple-v1.laz"));
  const auto las = allRecords(test::dataPath("points/simple.las"));
  ASSERT_EQ(las.size(), 1065u * 34);
  ASSERT_EQ(laz.size(), las.size());
  EXPECT_EQ(firstDifference(laz, las), las.size()) << "record " << firstDifference(laz, las) / 34;
}

}  // namespace
}  // namespace lodforge

namespace lodforge {
namespace {

// A point as the tests compare them across formats: coordinates in hundredths (both files use
// scale 0.01), intensity, classification (the class alone: formats 0–5 keep flags beside it)
// and RGB.
using Fields = std::tuple<std::int64_t, std::int64_t, std::int64_t, std::uint16_t, std::uint8_t,
                          std::uint16_t, std::uint16_t, std::uint16_t>;

std::vector<Fields> pointFields(const std::string& path) {
  Result<LasHeader> header = LasReader::readHeader(path);
  EXPECT_TRUE(header.ok());
  const std::vector<std::byte> records = allRecords(path);
  std::vector<Fields> fields;
  if (!header.ok()) return fields;
  const LasHeader& h = *header;
  const bool extended = h.pointFormat >= 6;
  const std::size_t rgbAt = extended ? 30 : 28;
  for (std::size_t at = 0; at + h.recordLength <= records.size(); at += h.recordLength) {
    const std::byte* r = records.data() + at;
    std::int64_t xyz[3];
    for (int k = 0; k < 3; ++k) {
      std::int32_t stored;
      std::memcpy(&stored, r + 4 * k, 4);
      xyz[k] = std::llround((stored * h.scale[k] + h.offset[k]) * 100);
    }
    std::uint16_t intensity, rgb[3];
    std::memcpy(&intensity, r + 12, 2);
    std::memcpy(rgb, r + rgbAt, 6);
    const auto cls = static_cast<std::uint8_t>(extended ? static_cast<std::uint8_t>(r[16])
                                                        : static_cast<std::uint8_t>(r[15]) & 31);
    fields.emplace_back(xyz[0], xyz[1], xyz[2], intensity, cls, rgb[0], rgb[1], rgb[2]);
  }
  std::sort(fields.begin(), fields.end());
  return fields;
}

TEST(Laz, LayeredCopcDecodesToTheSamePointsAsItsLasTwin) {
  const auto copc = pointFields(test::dataPath("points/1.2-with-color.copc.laz"));
  const auto las = pointFields(test::dataPath("points/1.2-with-color.las"));
  ASSERT_EQ(las.size(), 1065u);
  ASSERT_EQ(copc.size(), las.size());
  EXPECT_TRUE(copc == las);
}

}  // namespace
}  // namespace lodforge

namespace lodforge {
namespace {

std::string fileBytes(const std::string& path) {
  return test::readFile(path);
}

template <class T>
T peek(const std::string& bytes, std::size_t at) {
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof value);
  return value;
}
template <class T>
void poke(std::string& bytes, std::size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof value);
}

// Reads every point of a LAZ held in memory; the error, or an empty message when all is well.
std::string readError(const std::string& bytes) {
  const std::span<const std::byte> span(reinterpret_cast<const std::byte*>(bytes.data()),
                                        bytes.size());
  Result<LasReader> reader = LasReader::fromMemory(span, "damaged.laz");
  if (!reader) return reader.error().message;
  std::vector<std::byte> records;
  while (true) {
    Result<bool> more = reader->nextRecords(records);
    if (!more) {
      EXPECT_EQ(more.status().kind(), ErrorKind::kBadInput);
      return more.error().message;
    }
    if (!*more) return {};
  }
}

void expectDamage(const std::string& bytes, const std::vector<std::string>& parts) {
  const std::string message = readError(bytes);
  ASSERT_FALSE(message.empty()) << "the damage went unnoticed";
  EXPECT_EQ(message.rfind("damaged.laz: byte ", 0), 0u) << message;
  for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
}

TEST(Laz, UndamagedCopiesReadWhole) {
  EXPECT_EQ(readError(fileBytes(test::dataPath("points/autzen_trim.laz"))), "");
  EXPECT_EQ(readError(fileBytes(test::dataPath("points/1.2-with-color.copc.laz"))), "");
  EXPECT_EQ(readError(fileBytes(test::dataPath("points/simple-v1.laz"))), "");
}

TEST(Laz, DamagedChunksAreBadInputNamingChunkAndByte) {
  const std::string autzen = fileBytes(test::dataPath("points/autzen_trim.laz"));
  const auto pointOffset = peek<std::uint32_t>(autzen, 96);
  const auto tableAt = static_cast<std::size_t>(peek<std::int64_t>(autzen, pointOffset));
  {  // bytes in the middle of chunk 2 overwritten: the stream decodes to another length
    std::string bytes = autzen;
    const std::size_t at = pointOffset + 8 + (tableAt - pointOffset) * 3 / 5;
    for (std::size_t i = 0; i < 64; ++i) bytes[at + i] = static_cast<char>(i * 37);
    expectDamage(bytes, {"LAZ chunk 2 of 3", "damaged"});
  }
  {  // cut inside the last chunk: the table is gone with it
    std::string bytes = autzen.substr(0, (pointOffset + tableAt) / 2 + pointOffset / 2);
    expectDamage(bytes, {"chunk table", "outside the point data"});
  }
  {  // the table's pointer past the end of the file
    std::string bytes = autzen;
    poke<std::int64_t>(bytes, pointOffset, static_cast<std::int64_t>(autzen.size() + 100));
    expectDamage(bytes, {"chunk table is said to be at byte"});
  }
  {  // a header that counts one point more than the chunks hold
    std::string bytes = autzen;
    poke<std::uint32_t>(bytes, 107, peek<std::uint32_t>(autzen, 107) + 1);
    expectDamage(bytes,
                 {"LAZ chunk 3 of 3", "end after 10000 of the chunk's 10001", "point count"});
  }
}

TEST(Laz, AMissingChunkTableIsToleratedAsLaszipDoes) {
  // A writer that stopped before the table leaves the pointer at the chunks' start - 8: the
  // chunks are then found one after another by decoding them.
  std::string autzen = fileBytes(test::dataPath("points/autzen_trim.laz"));
  const auto pointOffset = peek<std::uint32_t>(autzen, 96);
  poke<std::int64_t>(autzen, pointOffset, static_cast<std::int64_t>(pointOffset));
  const std::span<const std::byte> span(reinterpret_cast<const std::byte*>(autzen.data()),
                                        autzen.size());
  Result<LasReader> reader = LasReader::fromMemory(span, "untabled.laz");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  std::vector<std::byte> all, records;
  while (true) {
    Result<bool> more = reader->nextRecords(records);
    ASSERT_TRUE(more.ok()) << more.status().message();
    if (!*more) break;
    all.insert(all.end(), records.begin(), records.end());
  }
  EXPECT_TRUE(all == allRecords(test::dataPath("points/autzen_trim.las")));
  // Without a table a slice would decode every chunk before it: refused, so that a job's rank 0
  // reads the file alone.
  Result<LasReader> sliced = LasReader::fromMemory(span, "untabled.laz");
  ASSERT_TRUE(sliced.ok());
  const Status restricted = sliced->restrictTo(60'000, 10);
  ASSERT_FALSE(restricted.ok());
  EXPECT_EQ(restricted.kind(), ErrorKind::kUnsupported);
  EXPECT_EQ(restricted.message(),
            "untabled.laz: a LAZ file without a chunk table is not read from a point on");
}

TEST(Laz, DamagedLayersAreBadInputNamingChunkAndByte) {
  const std::string copc = fileBytes(test::dataPath("points/1.2-with-color.copc.laz"));
  const std::size_t chunk = peek<std::uint32_t>(copc, 96) + 8;
  const std::size_t count = chunk + 36, sizes = count + 4;
  {  // the chunk's own count disagrees with the table
    std::string bytes = copc;
    poke<std::uint32_t>(bytes, count, peek<std::uint32_t>(copc, count) + 5);
    expectDamage(bytes, {"LAZ chunk 1 of", "points but the chunk table says"});
  }
  {  // a layer said to be larger than the chunk
    std::string bytes = copc;
    poke<std::uint32_t>(bytes, sizes + 4, 1u << 30);
    expectDamage(bytes, {"LAZ chunk 1 of", "layer 2 of", "runs past"});
  }
  {  // the x/y layer's bytes overwritten
    std::string bytes = copc;
    const std::size_t layers = sizes + 40;
    for (std::size_t i = 4; i < 40; ++i) bytes[layers + i] = static_cast<char>(0xA5 ^ i);
    expectDamage(bytes, {"LAZ chunk 1 of", "damaged"});
  }
}

}  // namespace
}  // namespace lodforge
