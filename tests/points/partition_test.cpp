#include "lodforge/points/partition.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>

#include <gtest/gtest.h>

#include "lodforge/core/file.h"
#include "lodforge/core/random.h"
#include "test_support.h"

namespace lodforge {
namespace {

// A text cloud of n points on a wavy sheet, some of them repeated exactly.
std::vector<Vec3d> writeCloud(const std::string& path, std::size_t n, std::uint64_t seed) {
  Random random(seed);
  std::vector<Vec3d> points;
  std::ofstream out(path);
  out.precision(17);
  for (std::size_t i = 0; i < n; ++i) {
    Vec3d p{random.uniform(0, 300), random.uniform(0, 100), 0};
    p.z = 5 * std::sin(p.x / 20) + random.uniform(-0.1, 0.1);
    if (i % 50 == 49) p = points[i / 2];  // duplicates
    points.push_back(p);
    out << p.x << ' ' << p.y << ' ' << p.z << '\n';
  }
  return points;
}

std::vector<CloudPoint> readBlock(const PointBlock& block) {
  std::vector<CloudPoint> points(block.count);
  std::ifstream in(block.path, std::ios::binary);
  in.read(reinterpret_cast<char*>(points.data()),
          static_cast<std::streamsize>(points.size() * sizeof(CloudPoint)));
  EXPECT_TRUE(in.good());
  return points;
}

using Multiset = std::map<std::tuple<double, double, double>, int>;

Multiset blocksContent(const Partition& partition, std::uint64_t blockSize) {
  Multiset content;
  for (const PointBlock& block : partition.blocks) {
    EXPECT_LE(block.count, blockSize);
    EXPECT_GT(block.count, 0u);
    Vec3d sum;
    for (const CloudPoint& p : readBlock(block)) {
      ++content[{p.position.x, p.position.y, p.position.z}];
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE(p.position[k], block.bounds.min[k]);
        EXPECT_LE(p.position[k], block.bounds.max[k]);
      }
      sum = sum + p.position;
    }
    const Vec3d centroid = sum * (1.0 / static_cast<double>(block.count));
    EXPECT_NEAR(length(centroid - block.centroid), 0, 1e-9);
  }
  return content;
}

TEST(Partition, EveryPointLandsInExactlyOneBlockOfAtMostTheBlockSize) {
  test::TempDir dir;
  const std::vector<Vec3d> input = writeCloud(dir.file("cloud.xyz"), 20'000, 3);
  Multiset want;
  for (const Vec3d& p : input) ++want[{p.x, p.y, p.z}];
  for (std::uint64_t blockSize : {1'000u, 3'333u, 50'000u}) {
    const std::string work = dir.file("work" + std::to_string(blockSize));
    std::filesystem::create_directories(work);
    PartitionOptions options;
    options.blockSize = blockSize;
    options.workDirectory = work;
    Result<Partition> partition = partitionPoints(dir.file("cloud.xyz"), options);
    ASSERT_TRUE(partition.ok()) << partition.error().message;
    EXPECT_EQ(partition->pointCount, input.size());
    EXPECT_EQ(blocksContent(*partition, blockSize), want);
    EXPECT_GE(partition->blocks.size(), input.size() / blockSize);
    EXPECT_EQ(partition->streamedPasses, 0);
  }
}

TEST(Partition, StreamedSplitsGiveTheSameBlocksAsSplitsInMemory) {
  test::TempDir dir;
  writeCloud(dir.file("cloud.xyz"), 12'000, 5);
  std::vector<std::vector<CloudPoint>> results[2];
  for (int streamed = 0; streamed < 2; ++streamed) {
    const std::string work = dir.file("work" + std::to_string(streamed));
    std::filesystem::create_directories(work);
    PartitionOptions options;
    options.blockSize = 700;
    options.workDirectory = work;
    // 2,000 points in memory at most: the top levels split by streaming their files.
    if (streamed) options.memoryBytes = 2'000 * sizeof(CloudPoint);
    Result<Partition> partition = partitionPoints(dir.file("cloud.xyz"), options);
    ASSERT_TRUE(partition.ok()) << partition.error().message;
    EXPECT_EQ(partition->streamedPasses > 0, streamed == 1);
    for (const PointBlock& b : partition->blocks) {
      std::vector<CloudPoint> points = readBlock(b);
      std::sort(points.begin(), points.end(), [](const CloudPoint& a, const CloudPoint& c) {
        return std::tie(a.position.x, a.position.y, a.position.z) <
               std::tie(c.position.x, c.position.y, c.position.z);
      });
      results[streamed].push_back(std::move(points));
    }
  }
  ASSERT_EQ(results[0].size(), results[1].size());
  for (std::size_t b = 0; b < results[0].size(); ++b) {
    ASSERT_EQ(results[0][b].size(), results[1][b].size()) << "block " << b;
    for (std::size_t i = 0; i < results[0][b].size(); ++i)
      EXPECT_EQ(results[0][b][i].position, results[1][b][i].position);
  }
}

// A block sink receives, from several threads, exactly the blocks the files would hold (in
// name order afterwards), and a failing sink fails the partition.
TEST(Partition, ASinkTakesTheBlocksInsteadOfFiles) {
  test::TempDir dir;
  writeCloud(dir.file("cloud.xyz"), 12'000, 7);
  PartitionOptions options;
  options.blockSize = 700;
  options.workDirectory = dir.file("files");
  options.memoryBytes = 3'000 * sizeof(CloudPoint);
  std::filesystem::create_directories(options.workDirectory);
  Result<Partition> files = partitionPoints(dir.file("cloud.xyz"), options);
  ASSERT_TRUE(files.ok()) << files.error().message;
  std::mutex mutex;
  std::map<std::string, Multiset> sunk;
  options.workDirectory = dir.file("sink");
  std::filesystem::create_directories(options.workDirectory);
  options.blockSink = [&](std::span<CloudPoint> points, PointBlock& block) {
    Multiset content;
    for (const CloudPoint& p : points) ++content[{p.position.x, p.position.y, p.position.z}];
    std::reverse(points.begin(), points.end());  // the sink may reorder
    std::lock_guard lock(mutex);
    EXPECT_EQ(block.count, points.size());
    sunk[block.name] = std::move(content);
    return Status{};
  };
  Result<Partition> sinks = partitionPoints(dir.file("cloud.xyz"), options);
  ASSERT_TRUE(sinks.ok()) << sinks.error().message;
  ASSERT_EQ(sinks->blocks.size(), files->blocks.size());
  for (std::size_t b = 0; b < files->blocks.size(); ++b) {
    const PointBlock &file = files->blocks[b], &sink = sinks->blocks[b];
    EXPECT_EQ(sink.name, file.name);
    EXPECT_EQ(sink.bounds, file.bounds);
    Multiset want;
    for (const CloudPoint& p : readBlock(file)) ++want[{p.position.x, p.position.y, p.position.z}];
    EXPECT_EQ(sunk.at(sink.name), want) << sink.name;
  }
  EXPECT_TRUE(std::filesystem::is_empty(options.workDirectory));  // no block files
  options.blockSink = [](std::span<CloudPoint>, PointBlock& block) -> Status {
    return ioError(block.name, "disk full");
  };
  Result<Partition> failed = partitionPoints(dir.file("cloud.xyz"), options);
  ASSERT_FALSE(failed.ok());
  EXPECT_NE(failed.error().message.find("disk full"), std::string::npos);
}

TEST(Partition, SplitsCoincidentPointsByCount) {
  // 5,000 copies of one point: no plane separates them, the median does.
  test::TempDir dir;
  {
    std::ofstream out(dir.file("same.xyz"));
    for (int i = 0; i < 5'000; ++i) out << "1 2 3\n";
  }
  PartitionOptions options;
  options.blockSize = 600;
  options.workDirectory = dir.path().string();
  Result<Partition> partition = partitionPoints(dir.file("same.xyz"), options);
  ASSERT_TRUE(partition.ok()) << partition.error().message;
  std::uint64_t total = 0;
  for (const PointBlock& b : partition->blocks) {
    EXPECT_LE(b.count, 600u);
    total += b.count;
  }
  EXPECT_EQ(total, 5'000u);
}

TEST(Partition, SplitPointsSeparatesAtThePlane) {
  Random random(8);
  std::vector<CloudPoint> points(1'000);
  for (CloudPoint& p : points) p.position = {random.uniform(-1, 1), random.uniform(-5, 5), 0};
  const std::size_t below = splitPoints(points, {1, 0.5});
  for (std::size_t i = 0; i < points.size(); ++i)
    EXPECT_EQ(points[i].position.y < 0.5, i < below) << i;
  Aabbd box;
  box.add(Vec3d{0, 0, 0});
  box.add(Vec3d{1, 3, 2});
  EXPECT_EQ(centroidSplit(box, {0.2, 0.7, 0.1}).axis, 1);
  EXPECT_DOUBLE_EQ(centroidSplit(box, {0.2, 0.7, 0.1}).value, 0.7);
}

TEST(Partition, RefusesAnEmptyInputAndBadPoints) {
  test::TempDir dir;
  test::writeFile(dir.file("empty.xyz"), "# nothing\n");
  PartitionOptions options;
  options.workDirectory = dir.path().string();
  Result<Partition> empty = partitionPoints(dir.file("empty.xyz"), options);
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.status().kind(), ErrorKind::kBadInput);
  EXPECT_NE(empty.error().message.find("no points"), std::string::npos);
  // A LAZ whose last chunk is cut off.
  const std::string laz = test::readFile(test::dataPath("points/autzen_trim.laz"));
  test::writeFile(dir.file("cut.laz"), laz.substr(0, laz.size() - 1000));
  Result<Partition> cut = partitionPoints(dir.file("cut.laz"), options);
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.status().kind(), ErrorKind::kBadInput);
  EXPECT_NE(cut.error().message.find("cut.laz: byte"), std::string::npos);
}

// A LAZ partitions like its LAS: the same points, attributes and all.
TEST(Partition, KeepsTheLidarAttributesOfLasAndLaz) {
  test::TempDir dir;
  for (const char* name : {"autzen_trim.las", "autzen_trim.laz"}) {
    PartitionOptions options;
    options.blockSize = 30'000;
    options.workDirectory = dir.path().string();
    Result<Partition> partition =
        partitionPoints(test::dataPath(std::string("points/") + name), options);
    ASSERT_TRUE(partition.ok()) << partition.error().message;
    EXPECT_EQ(partition->pointCount, 110'000u);
    EXPECT_NE(partition->info.attributes & kAttrGpsTime, 0u);
    EXPECT_EQ(partition->info.attributes & kAttrNir, 0u);
    std::uint64_t ground = 0, withTime = 0;
    for (const PointBlock& block : partition->blocks) {
      Result<std::vector<CloudPoint>> points = readPointRecords(block.path, 0, block.count);
      ASSERT_TRUE(points.ok());
      for (const CloudPoint& p : *points) {
        ground += p.attributes.classification == 2;
        withTime += p.attributes.gpsTime > 0;
        ASSERT_GE(p.attributes.returnNumber, 1);
      }
    }
    EXPECT_GT(ground, 10'000u) << name;
    EXPECT_EQ(withTime, 110'000u) << name;
  }
}

}  // namespace
}  // namespace lodforge
