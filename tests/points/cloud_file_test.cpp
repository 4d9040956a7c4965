#include "lodforge/points/cloud_file.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "lodforge/points/build.h"
#include "test_support.h"

namespace lodforge {
namespace {

void writeSheet(const std::string& path, std::size_t n, std::uint64_t seed) {
  Random random(seed);
  std::ofstream out(path);
  out.precision(12);
  out << "x,y,z,red,green,blue\n";
  for (std::size_t i = 0; i < n; ++i) {
    const double x = random.uniform(0, 200), y = random.uniform(0, 100);
    out << x + 500000 << ',' << y + 4e6 << ',' << 3 * std::sin(x / 15) * std::cos(y / 20) << ','
        << int(x) % 256 << ',' << int(y) % 256 << ",200\n";
  }
}

// Every point is reached exactly once from Part II through the segment files.
std::uint64_t pointsReached(const CloudFile& cloud) {
  std::uint64_t points = 0;
  for (std::size_t b = 0; b < cloud.blocks().size(); ++b) {
    Result<std::vector<ClusterNode>> segment = cloud.loadSegment(b);
    EXPECT_TRUE(segment.ok()) << (segment.ok() ? "" : segment.error().message);
    if (!segment.ok()) return 0;
    std::vector<std::uint32_t> queue;
    for (const ClusterNode& n : cloud.residentOf(b)) {
      if (n.leaf())
        ++points;
      else
        queue.push_back(n.firstChild);
    }
    for (std::size_t q = 0; q < queue.size(); ++q) {
      for (std::uint32_t s = queue[q]; s < queue[q] + 2; ++s) {
        if ((*segment)[s].leaf())
          ++points;
        else
          queue.push_back((*segment)[s].firstChild);
      }
    }
  }
  return points;
}

TEST(CloudFile, BuildWritesAPackageWhosePartsCoverEveryPoint) {
  test::TempDir dir;
  writeSheet(dir.file("sheet.csv"), 30'000, 1);
  PointsBuildOptions options;
  options.blockSize = 4'000;
  Result<PointsBuildStats> stats =
      buildPointCloud(dir.file("sheet.csv"), dir.file("s.lfc"), options);
  ASSERT_TRUE(stats.ok()) << stats.error().message;
  EXPECT_EQ(stats->points, 30'000u);
  EXPECT_GE(stats->blocks, 30'000u / 4'000);
  EXPECT_LE(stats->maxBlock, 4'000u);
  EXPECT_TRUE(stats->estimatedNormals);
  // The automatic tolerance keeps about 1/32 of the points as Part II.
  EXPECT_GT(stats->residentNodes, 30'000u / 32 / 3);
  EXPECT_LT(stats->residentNodes, 30'000u / 32 * 3);
  Result<CloudFile> cloud = CloudFile::open(dir.file("s.lfc"));
  ASSERT_TRUE(cloud.ok()) << cloud.error().message;
  const CloudHeader& h = cloud->header();
  EXPECT_EQ(h.pointCount, 30'000u);
  EXPECT_EQ(h.blockCount, stats->blocks);
  EXPECT_EQ(h.residentCount + h.segmentCount + h.droppedCount, 2 * 30'000u - h.blockCount);
  EXPECT_DOUBLE_EQ(h.tolerance, stats->tolerance);
  EXPECT_EQ(h.flags & kCloudInputColors, kCloudInputColors);
  EXPECT_EQ(pointsReached(*cloud), 30'000u);
  std::uint64_t blockPoints = 0;
  for (const CloudBlock& b : cloud->blocks()) {
    blockPoints += b.pointCount;
    EXPECT_LE(b.residentError, h.tolerance);
    // Node positions are relative to the block's origin and lie in its bounds.
  }
  EXPECT_EQ(blockPoints, 30'000u);
  for (std::size_t b = 0; b < cloud->blocks().size(); ++b) {
    const CloudBlock& block = cloud->blocks()[b];
    for (const ClusterNode& n : cloud->residentOf(b)) {
      const Vec3d p = block.origin + toDouble(n.position);
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE(p[k], block.bounds.min[k] - 1e-3);
        EXPECT_LE(p[k], block.bounds.max[k] + 1e-3);
      }
    }
  }
  // Nothing else left behind: the package, its segment directory, the input.
  std::size_t entries = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) {
    ++entries;
    EXPECT_TRUE(e.path().extension() == ".lfc" || e.path().extension() == ".lfs" ||
                e.path().extension() == ".csv")
        << e.path();
  }
  EXPECT_EQ(entries, 3u);
}

TEST(CloudFile, StreamedAndInMemoryBuildsAgree) {
  test::TempDir dir;
  writeSheet(dir.file("sheet.csv"), 20'000, 2);
  PointsBuildOptions options;
  options.blockSize = 3'000;
  options.tolerance = 0.05;
  ASSERT_TRUE(buildPointCloud(dir.file("sheet.csv"), dir.file("a.lfc"), options).ok());
  options.splitBytes = 5'000 * sizeof(CloudPoint);  // 5,000 points split in memory
  Result<PointsBuildStats> streamed =
      buildPointCloud(dir.file("sheet.csv"), dir.file("b.lfc"), options);
  ASSERT_TRUE(streamed.ok());
  EXPECT_GT(streamed->streamedPasses, 0);
  Result<CloudFile> a = CloudFile::open(dir.file("a.lfc")), b = CloudFile::open(dir.file("b.lfc"));
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->blocks().size(), b->blocks().size());
  ASSERT_EQ(a->resident().size(), b->resident().size());
  for (std::size_t i = 0; i < a->resident().size(); ++i) {
    EXPECT_EQ(a->resident()[i].pointCount, b->resident()[i].pointCount);
    // The same points per block in another order: sums round differently, nothing more.
    EXPECT_NEAR(a->resident()[i].error, b->resident()[i].error, 1e-5);
  }
}

TEST(CloudFile, RefusesCorruptAndMismatchedFiles) {
  test::TempDir dir;
  writeSheet(dir.file("sheet.csv"), 5'000, 3);
  PointsBuildOptions options;
  options.blockSize = 2'000;
  ASSERT_TRUE(buildPointCloud(dir.file("sheet.csv"), dir.file("a.lfc"), options).ok());
  ASSERT_TRUE(buildPointCloud(dir.file("sheet.csv"), dir.file("b.lfc"), options).ok());
  // One flipped byte anywhere in the package: the checksum catches it.
  {
    std::string bytes;
    {
      std::ifstream in(dir.file("a.lfc"), std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    for (std::size_t at : {std::size_t{40}, bytes.size() / 2, bytes.size() - 9}) {
      std::string bad = bytes;
      bad[at] = static_cast<char>(bad[at] ^ 0x10);
      test::writeFile(dir.file("bad.lfc"), bad);
      Result<CloudFile> cloud = CloudFile::open(dir.file("bad.lfc"));
      ASSERT_FALSE(cloud.ok()) << at;
      EXPECT_EQ(cloud.status().kind(), ErrorKind::kBadInput);
      EXPECT_NE(cloud.error().message.find("bad.lfc: byte"), std::string::npos);
    }
    test::writeFile(dir.file("short.lfc"), bytes.substr(0, 100));
    EXPECT_FALSE(CloudFile::open(dir.file("short.lfc")).ok());
  }
  // Segments of another build of the same input are refused (build ids differ).
  std::filesystem::remove_all(dir.file("a.lfs"));
  std::filesystem::copy(dir.file("b.lfs"), dir.file("a.lfs"));
  Result<CloudFile> a = CloudFile::open(dir.file("a.lfc"));
  ASSERT_TRUE(a.ok());
  Result<std::vector<ClusterNode>> segment = a->loadSegment(0);
  ASSERT_FALSE(segment.ok());
  EXPECT_NE(segment.error().message.find("another build"), std::string::npos);
  // A corrupted segment.
  const std::string path = dir.file("b.lfs") + "/" + segmentFileName(0);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(60);
    f.put('\x7f');
  }
  Result<CloudFile> b = CloudFile::open(dir.file("b.lfc"));
  ASSERT_TRUE(b.ok());
  Result<std::vector<ClusterNode>> broken = b->loadSegment(0);
  ASSERT_FALSE(broken.ok());
  EXPECT_NE(broken.error().message.find("checksum"), std::string::npos);
}

}  // namespace
}  // namespace lodforge
