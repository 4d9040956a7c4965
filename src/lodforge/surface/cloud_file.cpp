#include "lodforge/surface/cloud_file.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <queue>
#include <unordered_map>

#include <fmt/format.h>

#include "lodforge/core/progress.h"
#include "lodforge/io/points/point_reader.h"

namespace lodforge {

namespace {

constexpr std::size_t kBlockRecords = 1 << 15;

// A normal carried through `transform`: the image of a short step along it (the transforms are
// CRS to local metres, smooth at the scale of a metre).
Vec3f transformedNormal(const std::function<bool(Vec3d, Vec3d&)>& transform, Vec3d from, Vec3d to,
                        Vec3f normal) {
  Vec3d tip;
  if (!transform(from + toDouble(normal), tip)) return normal;
  return normalizeOr(toFloat(tip - to), normal);
}

// The local length of one input unit at `from` (placed at `to`): along x for a projected CRS,
// along z where x is in degrees (a geographic CRS: its heights are in metres or feet).
double unitScaleAt(const std::function<bool(Vec3d, Vec3d&)>& transform, Vec3d from, Vec3d to) {
  Vec3d step;
  if (!transform(from + Vec3d{1, 0, 0}, step)) return 1;
  const double along = length(step - to);
  if (along > 1e-3 && along < 1e3) return along;
  if (!transform(from + Vec3d{0, 0, 1}, step)) return 1;
  const double up = length(step - to);
  return up > 0 && std::isfinite(up) ? up : 1;
}

}  // namespace

Result<RecordWriter> RecordWriter::create(const std::string& path, std::size_t bufferBytes) {
  Result<OutputFile> file = OutputFile::create(path, bufferBytes);
  if (!file) return file.status();
  return RecordWriter(std::move(*file));
}

Result<CloudSummary> copyCloud(const std::string& input, const std::string& path,
                               bool salvageTruncated,
                               const std::function<bool(Vec3d, Vec3d&)>& transform) {
  Result<PointReader> reader =
      PointReader::open(input, {.salvageTruncated = salvageTruncated, .readExtras = false});
  if (!reader) return reader.status();
  Result<RecordWriter> out = RecordWriter::create(path, std::size_t{4} << 20);
  if (!out) return out.status();
  CloudSummary cloud;
  cloud.hasNormals = reader->info().hasNormals;
  cloud.hasColors = reader->info().hasColors;
  Progress progress("reconstruct: reading", reader->info().count.value_or(0));
  PointBatch batch;
  while (true) {
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) break;
    for (std::size_t i = 0; i < batch.size(); ++i) {
      CloudRecord r;
      r.id = cloud.count++;
      r.position = batch.positions[i];
      if (!batch.normals.empty()) r.normal = normalizeOr(batch.normals[i], Vec3f{0, 0, 1});
      if (transform) {
        if (!transform(batch.positions[i], r.position))
          return badInput(input, fmt::format("point {} ({:.3f}, {:.3f}, {:.3f}) cannot be placed "
                                             "in the local frame",
                                             r.id, batch.positions[i].x, batch.positions[i].y,
                                             batch.positions[i].z));
        if (!batch.normals.empty())
          r.normal = transformedNormal(transform, batch.positions[i], r.position, r.normal);
        if (r.id == 0) cloud.unitScale = unitScaleAt(transform, batch.positions[i], r.position);
      }
      cloud.bounds.add(r.position);
      if (!batch.colors.empty()) r.color = batch.colors[i];
      LODFORGE_TRY(out->add(r));
    }
    progress.advance(batch.size());
    LODFORGE_TRY(checkCancelled());
  }
  progress.finish();
  LODFORGE_TRY(out->finish());
  cloud.warnings = reader->info().warnings;
  if (reader->truncation())
    cloud.warnings.push_back(*reader->truncation() + "; read what came before");
  return cloud;
}

Status forEachRecordBlock(const std::string& path,
                          const std::function<Status(std::span<const CloudRecord>)>& each) {
  return forEachFileBlock<CloudRecord>(path, kBlockRecords, each);
}

Result<std::vector<CloudRecord>> readRecords(const std::string& path) {
  std::vector<CloudRecord> records;
  LODFORGE_TRY(forEachRecordBlock(path, [&](std::span<const CloudRecord> block) {
    records.insert(records.end(), block.begin(), block.end());
    return Status{};
  }));
  return records;
}

Status rewriteNormals(const std::string& path,
                      const std::function<Status(std::span<CloudRecord>)>& change) {
  Result<WorkFile> file = WorkFile::open(path);
  if (!file) return file.status();
  Result<std::uint64_t> bytes = fileSize(path);
  if (!bytes) return bytes.status();
  std::vector<CloudRecord> block(kBlockRecords);
  for (std::uint64_t at = 0; at < *bytes;) {
    const std::size_t n = static_cast<std::size_t>(
        std::min<std::uint64_t>(block.size(), (*bytes - at) / sizeof(CloudRecord)));
    if (n == 0) break;
    LODFORGE_TRY(file->readAt(at, block.data(), n * sizeof(CloudRecord)));
    LODFORGE_TRY(change(std::span<CloudRecord>(block.data(), n)));
    LODFORGE_TRY(file->writeAt(at, block.data(), n * sizeof(CloudRecord)));
    at += n * sizeof(CloudRecord);
    LODFORGE_TRY(checkCancelled());
  }
  return {};
}

namespace {

// An owned-normal file read back in blocks. Reading stops at the count written to it: a read
// that fails or ends before it is an error here, not a point found without a normal later.
class NormalStream {
 public:
  static Result<std::unique_ptr<NormalStream>> open(const OwnedNormalFile& file) {
    std::FILE* handle = std::fopen(file.path.c_str(), "rb");
    if (!handle) return ioErrorFromErrno(file.path, "open");
    std::unique_ptr<NormalStream> stream(new NormalStream(file, handle));
    LODFORGE_TRY(stream->refill());
    return stream;
  }
  NormalStream(const NormalStream&) = delete;
  NormalStream& operator=(const NormalStream&) = delete;
  ~NormalStream() { std::fclose(file_); }
  bool done() const { return at_ == got_; }
  const OwnedNormal& head() const { return block_[at_]; }
  Status pop() { return ++at_ == got_ ? refill() : Status{}; }

 private:
  NormalStream(const OwnedNormalFile& file, std::FILE* handle)
      : path_(file.path), records_(file.records), file_(handle) {}
  Status refill() {
    at_ = 0;
    const auto wanted =
        static_cast<std::size_t>(std::min<std::uint64_t>(block_.size(), records_ - read_));
    got_ = wanted == 0 ? 0 : std::fread(block_.data(), sizeof(OwnedNormal), wanted, file_);
    read_ += got_;
    if (got_ == wanted) return {};
    if (std::ferror(file_)) return ioErrorFromErrno(path_, "read");
    return Error{ErrorKind::kIo,
                 fmt::format("{}: byte {}: the file ends after {} of its {} normals", path_,
                             read_ * sizeof(OwnedNormal), read_, records_)};
  }

  std::string path_;
  std::uint64_t records_ = 0, read_ = 0;
  std::FILE* file_;
  std::vector<OwnedNormal> block_ = std::vector<OwnedNormal>(4096);
  std::size_t at_ = 0, got_ = 0;
};

}  // namespace

Status mergeNormals(const std::string& cloudPath, const std::vector<OwnedNormalFile>& files) {
  std::vector<std::unique_ptr<NormalStream>> streams;
  for (const OwnedNormalFile& file : files) {
    Result<std::unique_ptr<NormalStream>> stream = NormalStream::open(file);
    if (!stream) return stream.status();
    streams.push_back(std::move(*stream));
  }
  using Head = std::pair<std::uint64_t, std::size_t>;  // (id, stream)
  std::priority_queue<Head, std::vector<Head>, std::greater<>> heads;
  for (std::size_t s = 0; s < streams.size(); ++s)
    if (!streams[s]->done()) heads.emplace(streams[s]->head().id, s);
  LODFORGE_TRY(rewriteNormals(cloudPath, [&](std::span<CloudRecord> block) -> Status {
    for (CloudRecord& record : block) {
      // (Counts taken from the files' sizes, a job's ranks', make a file cut short land here.)
      if (heads.empty() || heads.top().first != record.id)
        return Error{ErrorKind::kIo, fmt::format("{}: point {} has no normal (is a normals file "
                                                 "of the work directory cut short?)",
                                                 cloudPath, record.id)};
      const std::size_t from = heads.top().second;
      heads.pop();
      NormalStream& s = *streams[from];
      record.normal = s.head().normal;
      LODFORGE_TRY(s.pop());
      if (!s.done()) heads.emplace(s.head().id, from);
    }
    return Status{};
  }));
  if (!heads.empty())
    return Error{ErrorKind::kIo,
                 fmt::format("{}: a normal for point {}, which {} does not have",
                             files[heads.top().second].path, heads.top().first, cloudPath)};
  std::error_code ignored;
  for (const OwnedNormalFile& file : files) std::filesystem::remove(file.path, ignored);
  return {};
}

namespace {

// Samples hashed into every cell of a coarse grid within one cell of them: a point then finds
// every sample within `cell` of it with one look-up.
class SampleGrid {
 public:
  SampleGrid(std::span<const CloudRecord> samples, const Aabbd& bounds, double cell)
      : origin_(bounds.min), cell_(cell) {
    for (std::uint32_t s = 0; s < samples.size(); ++s) {
      const std::array<std::int64_t, 3> c = cellOf(samples[s].position);
      for (std::int64_t dz = -1; dz <= 1; ++dz)
        for (std::int64_t dy = -1; dy <= 1; ++dy)
          for (std::int64_t dx = -1; dx <= 1; ++dx)
            cells_[key({c[0] + dx, c[1] + dy, c[2] + dz})].push_back(s);
    }
  }
  const std::vector<std::uint32_t>* near(const Vec3d& p) const {
    const auto at = cells_.find(key(cellOf(p)));
    return at == cells_.end() ? nullptr : &at->second;
  }

 private:
  std::array<std::int64_t, 3> cellOf(const Vec3d& p) const {
    return {static_cast<std::int64_t>(std::floor((p.x - origin_.x) / cell_)),
            static_cast<std::int64_t>(std::floor((p.y - origin_.y) / cell_)),
            static_cast<std::int64_t>(std::floor((p.z - origin_.z) / cell_))};
  }
  static std::uint64_t key(std::array<std::int64_t, 3> c) {
    // 21 bits an axis: the cell is never smaller than a millionth of the extent.
    const auto part = [](std::int64_t v) {
      return static_cast<std::uint64_t>(v + (std::int64_t{1} << 20)) & ((1u << 21) - 1);
    };
    return part(c[0]) | part(c[1]) << 21 | part(c[2]) << 42;
  }
  Vec3d origin_;
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

}  // namespace

Result<double> medianSpacingOfFile(const std::string& path, const CloudSummary& cloud,
                                   std::size_t samples) {
  assert(samples > 0);
  if (cloud.count < 2) return 0.0;
  const std::uint64_t step = std::max<std::uint64_t>(1, cloud.count / samples);
  std::vector<CloudRecord> picked;
  LODFORGE_TRY(forEachRecordBlock(path, [&](std::span<const CloudRecord> block) {
    for (const CloudRecord& r : block)
      if (r.id % step == 0) picked.push_back(r);
    return Status{};
  }));
  const Vec3d extent = cloud.bounds.max - cloud.bounds.min;
  const double diagonal = length(extent);
  // A first cell of a few mean spacings of points spread over the largest face of the bounds;
  // four times larger each time the median is not within a cell yet.
  const double face = std::max({extent.x * extent.y, extent.y * extent.z, extent.x * extent.z});
  double cell = std::max(diagonal * 1e-6, 4 * std::sqrt(face / static_cast<double>(cloud.count)));
  while (true) {
    const SampleGrid grid(picked, cloud.bounds, cell);
    std::vector<double> best(picked.size(), std::numeric_limits<double>::infinity());
    LODFORGE_TRY(forEachRecordBlock(path, [&](std::span<const CloudRecord> block) {
      for (const CloudRecord& r : block) {
        const std::vector<std::uint32_t>* near = grid.near(r.position);
        if (!near) continue;
        for (std::uint32_t s : *near) {
          const Vec3d d = r.position - picked[s].position;
          const double d2 = dot(d, d);
          if (d2 > 0 && d2 < best[s]) best[s] = d2;
        }
      }
      return Status{};
    }));
    std::nth_element(best.begin(), best.begin() + static_cast<std::ptrdiff_t>(best.size() / 2),
                     best.end());
    const double median = best[best.size() / 2];
    // Within a cell, every nearer point was seen: the median is exact.
    if (median <= cell * cell) return std::sqrt(median);
    if (cell > diagonal) return std::isfinite(median) ? std::sqrt(median) : 0.0;
    cell *= 4;
  }
}

}  // namespace lodforge
