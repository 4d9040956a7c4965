// LAZ decoding: the real LAZ and COPC files in ../shared/data decode to exactly the records of
// their LAS twins.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <tuple>
#include <vector>

#include "lodforge/io/las_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

std::vector<std::byte> allRecords(const std::string& path, std::size_t batch = 1 << 16) {
  Result<LasReader> reader = LasReader::open(path, batch);
  EXPECT_TRUE(reader.ok()) << reader.status().message();
  std::vector<std::byte> all, records;
  if (!reader.ok()) return all;
  while (true) {
    Result<bool> more = reader->nextRecords(records);
    EXPECT_TRUE(more.ok()) << more.status().message();
    if (!more.ok() || !*more) break;
    all.insert(all.end(), records.begin(), records.end());
  }
  return all;
}

std::size_t firstDifference(const std::vector<std::byte>& a, const std::vector<std::byte>& b) {
  return static_cast<std::size_t>(
      std::mismatch(a.begin(), a.end(), b.begin(), b.end()).first - a.begin());
}

TEST(Laz, PointwiseChunkedVersion2DecodesToTheLasRecords) {
  const auto laz = allRecords(test::dataPath("points/autzen_trim.laz"));
  const auto las = allRecords(test::dataPath("points/autzen_trim.las"));
  ASSERT_EQ(las.size(), 110000u * 34);
  ASSERT_EQ(laz.size(), las.size());
  EXPECT_EQ(firstDifference(laz, las), las.size()) << "record " << firstDifference(laz, las) / 34;
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
