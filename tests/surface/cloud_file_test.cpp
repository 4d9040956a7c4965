#include "lodforge/surface/cloud_file.h"

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

namespace lodforge {
namespace {

// A record file of `count` points (ids 0, 1, …) facing +z.
void writeCloud(const std::string& path, std::uint64_t count) {
  Result<RecordWriter> writer = RecordWriter::create(path);
  ASSERT_TRUE(writer.ok()) << writer.error().message;
  for (std::uint64_t id = 0; id < count; ++id) {
    CloudRecord r;
    r.id = id;
    r.position = {static_cast<double>(id), 0, 0};
    r.normal = {0, 0, 1};
    ASSERT_TRUE(writer->add(r).ok());
  }
  ASSERT_TRUE(writer->finish().ok());
}

// The normal point `id` is given: it differs from its neighbours'.
Vec3f normalOf(std::uint64_t id) {
  return normalizeOr(Vec3f{static_cast<float>(id % 7), static_cast<float>(id % 11), 1},
                     Vec3f{0, 0, 1});
}

// The owned-normal files of `runs` runs, point `id` owned by run id % runs, each in id order.
std::vector<OwnedNormalFile> writeNormals(const test::TempDir& dir, std::uint64_t count,
                                          std::uint64_t runs) {
  std::vector<OwnedNormalFile> files;
  for (std::uint64_t run = 0; run < runs; ++run) {
    OwnedNormalFile file{dir.file("run-" + std::to_string(run) + ".normals"), 0};
    std::string bytes;
    for (std::uint64_t id = run; id < count; id += runs) {
      const OwnedNormal owned{id, normalOf(id)};
      bytes.append(reinterpret_cast<const char*>(&owned), sizeof owned);
      ++file.records;
    }
    test::writeFile(file.path, bytes);
    files.push_back(file);
  }
  return files;
}

// Every record gets its own normal from whichever file holds it (over several read blocks), and
// the files are gone afterwards.
TEST(MergeNormals, EveryRecordGetsItsNormalAndTheFilesGo) {
  test::TempDir dir;
  const std::uint64_t count = 20'000;
  writeCloud(dir.file("cloud.points"), count);
  const std::vector<OwnedNormalFile> files = writeNormals(dir, count, 3);
  const Status merged = mergeNormals(dir.file("cloud.points"), files);
  ASSERT_TRUE(merged.ok()) << merged.error().message;
  Result<std::vector<CloudRecord>> records = readRecords(dir.file("cloud.points"));
  ASSERT_TRUE(records.ok()) << records.error().message;
  ASSERT_EQ(records->size(), count);
  for (const CloudRecord& r : *records) ASSERT_EQ(r.normal, normalOf(r.id)) << r.id;
  for (const OwnedNormalFile& file : files) EXPECT_FALSE(std::filesystem::exists(file.path));
}

// A normals file cut short (inside a record or between two, at the start or past a read block)
// is an I/O error naming the file and where it ends, not a point without a normal.
TEST(MergeNormals, AFileCutShortIsAnErrorNamingIt) {
  const std::uint64_t count = 20'000;
  for (const std::uint64_t keep : {0ull, 10ull, 5'000ull}) {
    for (const std::uint64_t partial : {0ull, 10ull}) {
      test::TempDir dir;
      writeCloud(dir.file("cloud.points"), count);
      const std::vector<OwnedNormalFile> files = writeNormals(dir, count, 2);
      std::filesystem::resize_file(files[1].path, keep * sizeof(OwnedNormal) + partial);
      const Status merged = mergeNormals(dir.file("cloud.points"), files);
      ASSERT_FALSE(merged.ok()) << keep << ' ' << partial;
      EXPECT_EQ(merged.error().kind, ErrorKind::kIo) << merged.error().message;
      EXPECT_EQ(merged.error().message,
                files[1].path + ": byte " + std::to_string(keep * sizeof(OwnedNormal)) +
                    ": the file ends after " + std::to_string(keep) + " of its 10000 normals");
    }
  }
}

// Counts taken from the files' sizes (a job's ranks wrote them): a file that lost whole records
// leaves a point without a normal, and one with a record too many a normal without a point;
// both are I/O errors naming what is missing.
TEST(MergeNormals, CountsFromSizesStillFindAShortOrALongFile) {
  for (const bool shorter : {true, false}) {
    test::TempDir dir;
    writeCloud(dir.file("cloud.points"), shorter ? 1'000 : 999);
    std::vector<OwnedNormalFile> files = writeNormals(dir, 1'000, 2);
    if (shorter) std::filesystem::resize_file(files[1].path, 400 * sizeof(OwnedNormal));
    for (OwnedNormalFile& file : files)
      file.records = std::filesystem::file_size(file.path) / sizeof(OwnedNormal);
    const Status merged = mergeNormals(dir.file("cloud.points"), files);
    ASSERT_FALSE(merged.ok()) << shorter;
    EXPECT_EQ(merged.error().kind, ErrorKind::kIo) << merged.error().message;
    EXPECT_EQ(merged.error().message,
              shorter ? dir.file("cloud.points") +
                            ": point 801 has no normal (is a normals file of the work directory "
                            "cut short?)"
                      : files[1].path + ": a normal for point 999, which " +
                            dir.file("cloud.points") + " does not have");
  }
}

// A file that cannot be read (a directory in its place) is an I/O error naming it.
TEST(MergeNormals, AFileThatCannotBeReadIsAnErrorNamingIt) {
  test::TempDir dir;
  writeCloud(dir.file("cloud.points"), 100);
  std::vector<OwnedNormalFile> files = writeNormals(dir, 100, 2);
  std::filesystem::remove(files[0].path);
  std::filesystem::create_directory(files[0].path);
  const Status merged = mergeNormals(dir.file("cloud.points"), files);
  ASSERT_FALSE(merged.ok());
  EXPECT_EQ(merged.error().kind, ErrorKind::kIo) << merged.error().message;
  EXPECT_EQ(merged.error().message, files[0].path + ": cannot read: Is a directory");
}

}  // namespace
}  // namespace lodforge
