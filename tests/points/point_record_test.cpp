#include "lodforge/points/point_record.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lodforge/io/points/point_reader.h"
#include "test_support.h"

namespace lodforge {
namespace {

// Every point of a file as the partition makes them (convertBatch's defaults for what is missing).
std::vector<CloudPoint> cloudPointsOf(const std::string& path, PointCloudInfo& info) {
  Result<PointReader> reader = PointReader::open(path, {.readExtras = false});
  EXPECT_TRUE(reader.ok()) << reader.error().message;
  info = reader->info();
  std::vector<CloudPoint> points;
  PointBatch batch;
  while (true) {
    Result<bool> more = reader->next(batch);
    EXPECT_TRUE(more.ok());
    if (!more.ok() || !*more) break;
    for (std::size_t i = 0; i < batch.size(); ++i) {
      CloudPoint p;
      p.position = batch.positions[i];
      p.normal = batch.normals.empty() ? Vec3f{} : batch.normals[i];
      p.color = batch.colors.empty() ? Rgba8{} : batch.colors[i];
      p.attributes = batch.attributes.empty() ? PointAttributes{} : batch.attributes[i];
      points.push_back(p);
    }
  }
  return points;
}

std::vector<CloudPoint> roundTrip(const PointRecordLayout& layout,
                                  std::span<const CloudPoint> points) {
  std::vector<std::byte> bytes(points.size() * layout.bytes());
  EXPECT_TRUE(layout.encode(points, bytes.data()).ok());
  std::vector<CloudPoint> back(points.size());
  layout.decode(bytes.data(), back);
  return back;
}

bool sameBits(std::span<const CloudPoint> a, std::span<const CloudPoint> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

TEST(PointRecord, ALasFilesPointsComeBackBitForBitFromTheirGridIn40Bytes) {
  for (const char* file : {"points/autzen_trim.las", "points/autzen_trim.laz"}) {
    PointCloudInfo info;
    const std::vector<CloudPoint> points = cloudPointsOf(test::dataPath(file), info);
    ASSERT_GT(points.size(), 1000u);
    ASSERT_TRUE(info.grid.has_value());
    const PointRecordLayout layout = PointRecordLayout::of(info, false);
    EXPECT_TRUE(layout.gridded());
    // Integers on the grid, a colour, the lidar fields: no normal.
    EXPECT_EQ(layout.bytes(), 12u + 4u + 24u) << file;
    EXPECT_TRUE(sameBits(roundTrip(layout, points), points)) << file;
    // Normals kept when the pipeline computes them: 12 bytes more as floats, 4 as bytes
    // (quantised tiles).
    EXPECT_EQ(PointRecordLayout::of(info, false, RecordNormals::kFloat).bytes(), 52u);
    EXPECT_EQ(PointRecordLayout::of(info, false, RecordNormals::kBytes).bytes(), 44u);
  }
}

TEST(PointRecord, PlacedOrGridlessPositionsStayDoubles) {
  PointCloudInfo info;
  std::vector<CloudPoint> points = cloudPointsOf(test::dataPath("points/autzen_trim.las"), info);
  points.resize(500);
  // A CRS moves the points off the file's grid: doubles, and any double comes back.
  const PointRecordLayout placed = PointRecordLayout::of(info, true);
  EXPECT_FALSE(placed.gridded());
  EXPECT_EQ(placed.bytes(), 24u + 4u + 24u);
  for (CloudPoint& p : points) p.position = p.position * 1.0000001 + Vec3d{0.1234567, 0, 0};
  EXPECT_TRUE(sameBits(roundTrip(placed, points), points));
  // The default layout is the whole 64-byte record.
  EXPECT_EQ(PointRecordLayout{}.bytes(), sizeof(CloudPoint));
  EXPECT_TRUE(sameBits(roundTrip(PointRecordLayout{}, points), points));
}

TEST(PointRecord, NormalBytesKeepEveryByteNormalExactlyAndOthersToHalfAStep) {
  PointCloudInfo info;
  info.grid = PointCloudInfo::Grid{{0.01, 0.01, 0.01}, {0, 0, 0}};
  const PointRecordLayout layout = PointRecordLayout::of(info, false, RecordNormals::kBytes);
  ASSERT_TRUE(layout.normalBytes());
  EXPECT_EQ(layout.bytes(), 12u + 4u);
  // An input's own normals stay floats (the clustering reads them).
  PointCloudInfo withNormals = info;
  withNormals.hasNormals = true;
  EXPECT_FALSE(PointRecordLayout::of(withNormals, false, RecordNormals::kBytes).normalBytes());
  EXPECT_EQ(PointRecordLayout::of(withNormals, false, RecordNormals::kBytes).bytes(), 24u);
  // Every normal of whole bytes over 127 (what tiles keep) comes back bit for bit: each byte
  // on each axis (they are encoded apart).
  std::vector<CloudPoint> bytesOnly;
  for (int q = -127; q <= 127; ++q) {
    CloudPoint p;
    p.normal =
        Vec3f{static_cast<float>(q), static_cast<float>(-q), static_cast<float>(q / 2)} / 127.0f;
    bytesOnly.push_back(p);
  }
  EXPECT_TRUE(sameBits(roundTrip(layout, bytesOnly), bytesOnly));
  // Any unit normal comes back within half a step (1/254) on each axis.
  std::mt19937 random(7);
  std::normal_distribution<float> gauss;
  std::vector<CloudPoint> units(2000);
  for (CloudPoint& p : units)
    p.normal = normalizeOr(Vec3f{gauss(random), gauss(random), gauss(random)}, Vec3f{0, 0, 1});
  const std::vector<CloudPoint> back = roundTrip(layout, units);
  for (std::size_t i = 0; i < units.size(); ++i) {
    const Vec3f d = back[i].normal - units[i].normal;
    EXPECT_LE(std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}), 0.5f / 127.0f + 1e-6f);
  }
}

TEST(PointRecord, APositionOffTheGridIsRefusedNotRounded) {
  PointCloudInfo info;
  info.grid = PointCloudInfo::Grid{{0.01, 0.01, 0.01}, {1000, 2000, 0}};
  const PointRecordLayout layout = PointRecordLayout::of(info, false);
  ASSERT_TRUE(layout.gridded());
  EXPECT_EQ(layout.bytes(), 12u);
  CloudPoint on;
  on.position = {1000 + 12345 * 0.01, 2000 + -7 * 0.01, 42 * 0.01};
  std::vector<std::byte> bytes(layout.bytes());
  EXPECT_TRUE(layout.encode(std::span(&on, 1), bytes.data()).ok());
  CloudPoint off = on;
  off.position.y += 0.004;
  const Status refused = layout.encode(std::span(&off, 1), bytes.data());
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().kind, ErrorKind::kInternal);
  EXPECT_NE(refused.error().message.find("not on the input's grid"), std::string::npos);
  // What the layout leaves out comes back as the defaults.
  CloudPoint back;
  back.color = {1, 2, 3, 4};
  back.normal = {1, 0, 0};
  EXPECT_TRUE(layout.encode(std::span(&on, 1), bytes.data()).ok());
  layout.decode(bytes.data(), std::span(&back, 1));
  EXPECT_EQ(back.position, on.position);
  EXPECT_EQ(back.color, Rgba8{});
  EXPECT_EQ(back.normal, Vec3f{});
  EXPECT_EQ(back.attributes.gpsTime, 0.0);
}

}  // namespace
}  // namespace lodforge
