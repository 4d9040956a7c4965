#include "lodforge/points/partition.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>

#include <fmt/format.h>
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
  Result<std::vector<CloudPoint>> points =
      readPointRecords(block.path, block.layout, block.first, block.count);
  EXPECT_TRUE(points.ok()) << points.error().message;
  return points.ok() ? std::move(*points) : std::vector<CloudPoint>{};
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

// The blocks of a cloud, each sorted by position, with `inMemory` points split in memory at
// most (0: all of them).
std::vector<std::vector<CloudPoint>> sortedBlocks(const std::string& input, const std::string& work,
                                                  std::uint64_t blockSize, std::uint64_t inMemory,
                                                  int& streamedPasses) {
  std::filesystem::create_directories(work);
  PartitionOptions options;
  options.blockSize = blockSize;
  options.workDirectory = work;
  if (inMemory > 0) options.memoryBytes = inMemory * sizeof(CloudPoint);
  Result<Partition> partition = partitionPoints(input, options);
  EXPECT_TRUE(partition.ok()) << partition.error().message;
  if (!partition) return {};
  streamedPasses = partition->streamedPasses;
  std::vector<std::vector<CloudPoint>> blocks;
  for (const PointBlock& b : partition->blocks) {
    std::vector<CloudPoint> points = readBlock(b);
    std::sort(points.begin(), points.end(), [](const CloudPoint& a, const CloudPoint& c) {
      return std::tie(a.position.x, a.position.y, a.position.z) <
             std::tie(c.position.x, c.position.y, c.position.z);
    });
    blocks.push_back(std::move(points));
  }
  return blocks;
}

void expectSameBlocks(const std::vector<std::vector<CloudPoint>>& a,
                      const std::vector<std::vector<CloudPoint>>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].size(), b[k].size()) << "block " << k;
    for (std::size_t i = 0; i < a[k].size(); ++i) EXPECT_EQ(a[k][i].position, b[k][i].position);
  }
}

TEST(Partition, StreamedSplitsGiveTheSameBlocksAsSplitsInMemory) {
  test::TempDir dir;
  writeCloud(dir.file("cloud.xyz"), 12'000, 5);
  int passes[2] = {0, 0};
  const auto inMemory = sortedBlocks(dir.file("cloud.xyz"), dir.file("work0"), 700, 0, passes[0]);
  // 2,000 points in memory at most: the top levels split by streaming their ranges.
  const auto streamed =
      sortedBlocks(dir.file("cloud.xyz"), dir.file("work1"), 700, 2'000, passes[1]);
  EXPECT_EQ(passes[0], 0);
  EXPECT_GT(passes[1], 0);
  expectSameBlocks(inMemory, streamed);
}

// Streamed splits rewrite a node's range in place from both ends, a chunk (16,384 points) at a
// time: inputs many chunks long whose points lie all above the first plane first, all below
// first, or alternate by runs still give the blocks of an in-memory split.
TEST(Partition, InPlaceSplitsHandleAnyOrderOfTheFile) {
  test::TempDir dir;
  Random random(9);
  std::vector<Vec3d> points(90'000);
  for (Vec3d& p : points)
    p = {random.uniform(0, 400), random.uniform(0, 100), random.uniform(0, 1)};
  for (int order = 0; order < 3; ++order) {
    SCOPED_TRACE(order);
    if (order == 0)
      std::sort(points.begin(), points.end(), [](auto& a, auto& b) { return a.x > b.x; });
    if (order == 1)
      std::sort(points.begin(), points.end(), [](auto& a, auto& b) { return a.x < b.x; });
    if (order == 2)  // runs of 20,000 alternating sides
      std::sort(points.begin(), points.end(), [](auto& a, auto& b) {
        return std::tuple(int(a.x) % 2, a.x) < std::tuple(int(b.x) % 2, b.x);
      });
    const std::string input = dir.file(fmt::format("cloud{}.xyz", order));
    {
      std::ofstream out(input);
      out.precision(17);
      for (const Vec3d& p : points) out << p.x << ' ' << p.y << ' ' << p.z << '\n';
    }
    int passes[2] = {0, 0};
    const auto inMemory =
        sortedBlocks(input, dir.file(fmt::format("m{}", order)), 5'000, 0, passes[0]);
    const auto streamed =
        sortedBlocks(input, dir.file(fmt::format("s{}", order)), 5'000, 10'000, passes[1]);
    EXPECT_GE(passes[1], 3);
    expectSameBlocks(inMemory, streamed);
  }
}

// A block sink receives, from several threads, exactly the blocks the partition holds (in
// name order afterwards); what it leaves in the points is written back; a failing sink fails
// the partition.
TEST(Partition, ASinkSeesEveryBlockAndItsOrderIsWrittenBack) {
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
  std::map<std::string, Vec3d> lastOf;
  options.workDirectory = dir.file("sink");
  std::filesystem::create_directories(options.workDirectory);
  options.blockSink = [&](std::span<CloudPoint> points, std::span<std::uint32_t> ids,
                          PointBlock& block) {
    EXPECT_TRUE(ids.empty());  // the input has no extra fields
    Multiset content;
    for (const CloudPoint& p : points) ++content[{p.position.x, p.position.y, p.position.z}];
    std::reverse(points.begin(), points.end());  // the sink may reorder
    std::lock_guard lock(mutex);
    EXPECT_EQ(block.count, points.size());
    sunk[block.name] = std::move(content);
    lastOf[block.name] = points.back().position;
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
    EXPECT_EQ(readBlock(sink).back().position, lastOf.at(sink.name)) << sink.name;
  }
  options.blockSink = [](std::span<CloudPoint>, std::span<std::uint32_t>,
                         PointBlock& block) -> Status { return ioError(block.name, "disk full"); };
  Result<Partition> failed = partitionPoints(dir.file("cloud.xyz"), options);
  ASSERT_FALSE(failed.ok());
  EXPECT_NE(failed.error().message.find("disk full"), std::string::npos);
}

// A PLY of `points` with one extra property: each point's index in the file (an int, so that
// the partition carries 4 extra bytes a point). The index is in the normal's x too, so that
// coincident points can be told apart.
void writeIndexedPly(const std::string& path, const std::vector<Vec3d>& points) {
  std::ofstream out(path);
  out.precision(17);
  out << "ply\nformat ascii 1.0\nelement vertex " << points.size()
      << "\nproperty double x\nproperty double y\nproperty double z\nproperty float nx\n"
         "property float ny\nproperty float nz\nproperty int index\nend_header\n";
  for (std::size_t i = 0; i < points.size(); ++i)
    out << points[i].x << ' ' << points[i].y << ' ' << points[i].z << ' ' << i << " 0 1 " << i
        << '\n';
}

// Extra fields travel in step with their points through every reorder: the reading pass,
// streamed splits, in-memory splits (the median fallback too: a tenth of the points coincide)
// and a sink that shuffles the points and their ids.
TEST(Partition, ExtraBytesFollowTheirPointsThroughEveryReorder) {
  test::TempDir dir;
  Random random(31);
  std::vector<Vec3d> points;
  for (int i = 0; i < 40'000; ++i) {
    points.push_back(
        i % 10 == 0 ? Vec3d{7, 7, 7}
                    : Vec3d{random.uniform(0, 100), random.uniform(0, 50), random.uniform(0, 2)});
  }
  writeIndexedPly(dir.file("cloud.ply"), points);
  for (const std::uint64_t memory : {std::uint64_t{0}, std::uint64_t{6'000}}) {
    PartitionOptions options;
    options.blockSize = 900;
    options.workDirectory = dir.file(fmt::format("w{}", memory));
    options.carryExtras = true;
    if (memory != 0) options.memoryBytes = memory * sizeof(CloudPoint);
    std::filesystem::create_directories(options.workDirectory);
    std::mutex mutex;
    std::uint64_t shuffled = 0;
    options.blockSink = [&](std::span<CloudPoint> block, std::span<std::uint32_t> ids,
                            PointBlock&) {
      EXPECT_EQ(ids.size(), block.size());
      Random order(block.size());
      for (std::size_t i = block.size(); i > 1; --i) {
        const auto j = static_cast<std::size_t>(order.uniform(0, static_cast<double>(i)));
        std::swap(block[i - 1], block[std::min(j, i - 1)]);
        std::swap(ids[i - 1], ids[std::min(j, i - 1)]);
      }
      std::lock_guard lock(mutex);
      shuffled += block.size();
      return Status{};
    };
    Result<Partition> partition = partitionPoints(dir.file("cloud.ply"), options);
    ASSERT_TRUE(partition.ok()) << partition.error().message;
    EXPECT_EQ(shuffled, points.size());
    if (memory != 0) {
      EXPECT_GE(partition->streamedPasses, 2);
    }
    ASSERT_EQ(partition->info.extras.stride, 4u);
    ASSERT_EQ(partition->info.extras.fields.size(), 1u);
    EXPECT_EQ(partition->info.extras.fields[0].name, "index");
    std::vector<int> seen(points.size(), 0);
    for (const PointBlock& block : partition->blocks) {
      Result<std::vector<std::byte>> extras =
          readExtraRecords(partition->extrasPath, 4, block.first, block.count);
      ASSERT_TRUE(extras.ok()) << extras.error().message;
      const std::vector<CloudPoint> records = readBlock(block);
      for (std::size_t i = 0; i < records.size(); ++i) {
        std::int32_t index = -1;
        std::memcpy(&index, extras->data() + 4 * i, 4);
        ASSERT_TRUE(index >= 0 && index < static_cast<std::int32_t>(points.size()));
        ++seen[static_cast<std::size_t>(index)];
        EXPECT_EQ(records[i].position, points[static_cast<std::size_t>(index)])
            << block.name << " record " << i;
        EXPECT_EQ(records[i].normal.x, static_cast<float>(index)) << block.name << " record " << i;
      }
    }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<std::ptrdiff_t>(points.size()));
  }
  // Not asked for: not read, no second work file.
  PartitionOptions plain;
  plain.workDirectory = dir.file("plain");
  std::filesystem::create_directories(plain.workDirectory);
  Result<Partition> without = partitionPoints(dir.file("cloud.ply"), plain);
  ASSERT_TRUE(without.ok()) << without.error().message;
  EXPECT_EQ(without->info.extras.stride, 0u);
  EXPECT_TRUE(without->extrasPath.empty());
  EXPECT_FALSE(std::filesystem::exists(plain.workDirectory + "/b.extras"));
}

// The reading pass works on several batches at once: of two points in different batches that
// cannot be placed, the first in the file is named, whichever failed first.
TEST(Partition, AFailedPlacementNamesThePointFirstInTheFile) {
  test::TempDir dir;
  const std::vector<Vec3d> input = writeCloud(dir.file("cloud.xyz"), 3 * kInputBatchPoints, 8);
  const Vec3d first = input[kInputBatchPoints + 100], second = input[2 * kInputBatchPoints + 7];
  ASSERT_NE(first, second);
  PartitionOptions options;
  options.workDirectory = dir.file("work");
  std::filesystem::create_directories(options.workDirectory);
  options.transform = [&](Vec3d in, Vec3d& out) {
    out = in;
    return in != first && in != second;
  };
  Result<Partition> partition = partitionPoints(dir.file("cloud.xyz"), options);
  ASSERT_FALSE(partition.ok());
  EXPECT_EQ(partition.error().kind, ErrorKind::kBadInput);
  // Its first occurrence (the cloud repeats some points).
  const auto named = std::find(input.begin(), input.end(), first) - input.begin();
  EXPECT_GE(named, static_cast<std::ptrdiff_t>(kInputBatchPoints));
  EXPECT_NE(partition.error().message.find(fmt::format("point {} (", named)), std::string::npos)
      << partition.error().message;
}

TEST(Partition, SplitsCoincidentPointsByCount) {
  // 5,000 copies of one point: no plane separates them, the median does. And a cloud where only
  // a node further down is flat (3,000 copies beside 2,000 points along x). Every block's bounds
  // and centroid are its points' (a median split sums its halves' stats afresh).
  test::TempDir dir;
  std::map<std::string, Multiset> clouds;
  {
    std::ofstream same(dir.file("same.xyz")), mixed(dir.file("mixed.xyz"));
    for (int i = 0; i < 5'000; ++i) {
      same << "1 2 3\n";
      ++clouds["same"][{1, 2, 3}];
      const double x = i < 3'000 ? 1 : 10 + i % 97;
      mixed << x << " 2 3\n";
      ++clouds["mixed"][{x, 2, 3}];
    }
  }
  for (const auto& [name, want] : clouds) {
    const std::string work = dir.file(name + ".work");
    std::filesystem::create_directories(work);
    PartitionOptions options;
    options.blockSize = 600;
    options.workDirectory = work;
    Result<Partition> partition = partitionPoints(dir.file(name + ".xyz"), options);
    ASSERT_TRUE(partition.ok()) << partition.error().message;
    EXPECT_EQ(blocksContent(*partition, 600), want) << name;
  }
}

TEST(Partition, SplitPointsSeparatesAtThePlane) {
  Random random(8);
  std::vector<CloudPoint> points(1'000);
  for (CloudPoint& p : points) p.position = {random.uniform(-1, 1), random.uniform(-5, 5), 0};
  const std::vector<CloudPoint> original = points;
  std::vector<CloudPoint> plain = points;
  std::vector<std::uint32_t> ids(points.size());
  std::iota(ids.begin(), ids.end(), 0u);
  const std::size_t below = splitPoints(points, {1, 0.5}, ids);
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(points[i].position.y < 0.5, i < below) << i;
    EXPECT_EQ(points[i].position, original[ids[i]].position) << i;  // ids moved in step
  }
  // The same order with ids as without (and as std::partition leaves it).
  EXPECT_EQ(splitPoints(plain, {1, 0.5}), below);
  std::vector<CloudPoint> standard = original;
  std::partition(standard.begin(), standard.end(),
                 [](const CloudPoint& p) { return p.position.y < 0.5; });
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(plain[i].position, points[i].position) << i;
    EXPECT_EQ(standard[i].position, points[i].position) << i;
  }
  // All on one side: the median split moves the ids too.
  std::vector<CloudPoint> same = original;
  for (CloudPoint& p : same) p.position.x = 3;
  std::iota(ids.begin(), ids.end(), 0u);
  const std::size_t half = splitPoints(same, {0, 3.0}, ids);
  EXPECT_EQ(half, same.size() / 2);
  for (std::size_t i = 0; i < same.size(); ++i)
    EXPECT_EQ(same[i].position.y, original[ids[i]].position.y) << i;
  Aabbd box;
  box.add(Vec3d{0, 0, 0});
  box.add(Vec3d{1, 3, 2});
  EXPECT_EQ(centroidSplit(box, {0.2, 0.7, 0.1}).axis, 1);
  EXPECT_DOUBLE_EQ(centroidSplit(box, {0.2, 0.7, 0.1}).value, 0.7);
}

// The block scheme against std::partition: sizes around its blocks (64 a side), every share of
// points below, and clustered sides; each point seen once, on the side where it ends.
TEST(Partition, SplitRecordsLeavesStdPartitionsOrderAndSettlesEachPointOnce) {
  Random random(21);
  for (const std::size_t n : {0, 1, 2, 63, 64, 127, 128, 129, 130, 200, 257, 1'000, 20'000}) {
    for (const double share : {0.0, 0.01, 0.3, 0.5, 0.97, 1.0}) {
      std::vector<CloudPoint> points(n);
      for (std::size_t i = 0; i < n; ++i) {
        // Odd sizes in a descending run: every pair of ends swaps, block after block.
        const double u = n % 2 == 0 ? random.uniform(0, 1) : 1 - double(i) / double(n);
        points[i].position = {u, double(i), 0};
      }
      std::vector<CloudPoint> standard = points;
      const auto below = [&](const CloudPoint& p) { return p.position.x < share; };
      const auto end = std::partition(standard.begin(), standard.end(), below);
      std::vector<std::uint32_t> ids(n);
      std::iota(ids.begin(), ids.end(), 0u);
      std::vector<int> seen(n, 0);
      const std::vector<CloudPoint> original = points;
      const std::size_t half = hoarePartition(
          std::span(points), std::span(ids), [&](std::size_t i) { return below(points[i]); },
          [&](const CloudPoint& p, int side) {
            const auto i = static_cast<std::size_t>(p.position.y);
            seen[i] += 1;
            EXPECT_EQ(below(p), side == 0) << n << " " << share << " " << i;
          });
      ASSERT_EQ(half, static_cast<std::size_t>(end - standard.begin())) << n << " " << share;
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(points[i].position, standard[i].position) << n << " " << share << " " << i;
        ASSERT_EQ(points[i].position, original[ids[i]].position) << i;
        ASSERT_EQ(seen[i], 1) << n << " " << share << " " << i;
      }
    }
  }
  // Every point on one side: the callback sees each there once (splitWithStats tells the median
  // split by that), then the median splits by count.
  std::vector<CloudPoint> line(300);
  for (std::size_t i = 0; i < line.size(); ++i) line[i].position = {1 - double(i) / 300, 0, 0};
  std::array<std::size_t, 2> sides{};
  const std::size_t half = splitRecords(std::span(line), {0, 2.0}, {}, false,
                                        [&](const CloudPoint&, int side) { ++sides[side]; });
  EXPECT_EQ(half, 150u);
  EXPECT_EQ(sides[0], 300u);
  EXPECT_EQ(sides[1], 0u);
  for (std::size_t i = 0; i < line.size(); ++i)
    EXPECT_EQ(line[i].position.x < line[half].position.x, i < half) << i;
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
      Result<std::vector<CloudPoint>> points =
          readPointRecords(block.path, block.layout, block.first, block.count);
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
