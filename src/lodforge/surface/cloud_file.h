// The cloud as reconstruction works on it out of core: fixed records (input index, position,
// normal, colour) in files of our own, read and written in blocks. The input is read once
// into such a file (LAZ decodes once); runs of chunks get files of the records they need, and
// normals estimated run by run come back into it from files of their own.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/core/math.h"
#include "lodforge/core/status.h"

namespace lodforge {

struct CloudRecord {
  std::uint64_t id = 0;  // index in the input: the order every sum over points follows
  Vec3d position;
  Vec3f normal;
  Rgba8 color;
};
static_assert(sizeof(CloudRecord) == 48);

struct CloudSummary {
  std::uint64_t count = 0;
  Aabbd bounds;
  bool hasNormals = false, hasColors = false;
  // The local frame's length of one of the input's units (0.3048 for a CRS in feet; 1 without
  // a transform): lengths the user gives in the cloud's units are multiplied by it.
  double unitScale = 1;
  // What the reader read past (a PLY's other elements, a LAS's unreadable extra bytes) and where
  // a salvaged input was cut short: for the command to print.
  std::vector<std::string> warnings;
};

// Reads `input` (any point format) into the record file `path`, normals made unit (+z where the
// input has none), colours white where it has none.
Result<CloudSummary> copyCloud(const std::string& input, const std::string& path,
                               bool salvageTruncated,
                               const std::function<bool(Vec3d, Vec3d&)>& transform = {});

// Records appended in blocks; the file appears under its name at finish().
class RecordWriter {
 public:
  static Result<RecordWriter> create(const std::string& path, std::size_t bufferBytes = 1 << 20);
  Status add(const CloudRecord& record) { return file_.write(&record, sizeof record); }
  Status finish() { return file_.commit(); }
  std::uint64_t records() const { return file_.bytesWritten() / sizeof(CloudRecord); }

 private:
  explicit RecordWriter(OutputFile file) : file_(std::move(file)) {}
  OutputFile file_;
};

// Calls `each` with the file's records a block at a time, in file order.
Status forEachRecordBlock(const std::string& path,
                          const std::function<Status(std::span<const CloudRecord>)>& each);

// All records of a file.
Result<std::vector<CloudRecord>> readRecords(const std::string& path);

// Rewrites each record's normal in place: normals[i] for the i-th record (by file position).
Status rewriteNormals(const std::string& path,
                      const std::function<Status(std::span<CloudRecord>)>& change);

// A point's normal estimated by the run that owns it, for the record with that id.
struct OwnedNormal {
  std::uint64_t id = 0;
  Vec3f normal;
  std::uint32_t unused = 0;
};
static_assert(sizeof(OwnedNormal) == 24);

// A file of OwnedNormal in id order, and how many were written to it.
struct OwnedNormalFile {
  std::string path;
  std::uint64_t records = 0;
};

// Sets every record's normal in the record file from `files` (together one normal per record),
// then removes them. A file that cannot be read, or holds fewer normals than were written to
// it, is an I/O error naming it and where it ends; so is a record left without a normal (files
// whose counts were taken from their sizes) or a normal left without a record.
Status mergeNormals(const std::string& cloudPath, const std::vector<OwnedNormalFile>& files);

// The median distance from a point to its nearest other point, over up to `samples` points
// spread through the file (the same points and the same value as medianSpacing over the cloud in
// memory), found in passes over the file with the samples hashed in a coarse grid: memory for
// the samples only. 0 when no sample has a distinct neighbour.
Result<double> medianSpacingOfFile(const std::string& path, const CloudSummary& cloud,
                                   std::size_t samples = 10'000);

}  // namespace lodforge
