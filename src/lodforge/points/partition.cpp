#include "lodforge/points/partition.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <mutex>
#include <numeric>
#include <optional>

#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_group.h>

#include "lodforge/core/file.h"
#include "lodforge/core/pipeline_failure.h"
#include "lodforge/core/progress.h"

namespace lodforge {

namespace {

using PartNode = PartitionNode;

struct Stats {
  std::uint64_t count = 0;
  Aabbd bounds;
  Vec3d sum;
  void add(const Vec3d& position) {
    ++count;
    bounds.add(position);
    sum = sum + position;
  }
  void add(const CloudPoint& p) { add(p.position); }
};

Vec3d centroidOf(const Vec3d& sum, std::uint64_t count) {
  return sum * (1.0 / static_cast<double>(std::max<std::uint64_t>(1, count)));
}

// The work files: the points (records of `layout`) and, when the input has extra fields, their
// bytes in step.
struct WorkFiles {
  const WorkFile& points;
  const PointRecordLayout& layout;
  const WorkFile* extras = nullptr;
  std::size_t stride = 0;  // extra bytes a point

  std::uint64_t at(std::uint64_t record) const { return record * layout.bytes(); }
  // Records [first, first + out.size()) into `out`, a slice at a time through `scratch`.
  Status readPoints(std::uint64_t first, std::span<CloudPoint> out,
                    std::vector<std::byte>& scratch) const {
    for (std::size_t done = 0; done < out.size(); done += kSlice) {
      const std::size_t n = std::min(kSlice, out.size() - done);
      scratch.resize(n * layout.bytes());
      LODFORGE_TRY(points.readAt(at(first + done), scratch.data(), scratch.size()));
      layout.decode(scratch.data(), out.subspan(done, n));
    }
    return {};
  }
  // The same with the slices in parallel, for a node loaded for the in-memory splits (one
  // thread copied it out of the page cache and decoded it while the other waited).
  Status readPointsInParallel(std::uint64_t first, std::span<CloudPoint> out) const {
    std::vector<Status> read((out.size() + kSlice - 1) / kSlice);
    tbb::parallel_for(std::size_t{0}, read.size(), [&](std::size_t slice) {
      const std::size_t done = slice * kSlice, n = std::min(kSlice, out.size() - done);
      std::vector<std::byte> scratch;
      read[slice] = readPoints(first + done, out.subspan(done, n), scratch);
    });
    for (const Status& status : read) LODFORGE_TRY(status);
    return {};
  }
  Status writePoints(std::uint64_t first, std::span<const CloudPoint> in,
                     std::vector<std::byte>& scratch) const {
    for (std::size_t done = 0; done < in.size(); done += kSlice) {
      const std::size_t n = std::min(kSlice, in.size() - done);
      scratch.resize(n * layout.bytes());
      LODFORGE_TRY(layout.encode(in.subspan(done, n), scratch.data()));
      LODFORGE_TRY(points.writeAt(at(first + done), scratch.data(), scratch.size()));
    }
    return {};
  }
  static constexpr std::size_t kSlice = std::size_t{1} << 14;
};

// Consecutive records in memory: the points and, in step, their extra bytes.
struct Records {
  std::size_t stride = 0;
  std::vector<CloudPoint> points;
  std::vector<std::byte> extras;

  std::size_t size() const { return points.size(); }
  void resize(std::size_t n) {
    points.resize(n);
    extras.resize(n * stride);
  }
  // n records from record `first` of the files (the points' slices in parallel).
  Status read(const WorkFiles& files, std::uint64_t first, std::size_t n) {
    resize(n);
    LODFORGE_TRY(files.readPointsInParallel(first, points));
    if (stride == 0) return {};
    return files.extras->readAt(first * stride, extras.data(), n * stride);
  }
};

// Consecutive records as the files hold them (encoded), and their extra bytes in step: the
// streamed splits move them without decoding (decode and encode were 37 % of that phase).
struct RawRecords {
  std::size_t bytes = 0, stride = 0;  // of a record, of its extra bytes
  std::vector<std::byte> points, extras;

  std::size_t size() const { return points.size() / bytes; }
  const std::byte* record(std::size_t i) const { return points.data() + i * bytes; }
  void resize(std::size_t n) {
    points.resize(n * bytes);
    extras.resize(n * stride);
  }
  void push(const RawRecords& from, std::size_t i) {
    points.insert(points.end(), from.record(i), from.record(i) + bytes);
    if (stride == 0) return;
    const std::byte* e = from.extras.data() + i * stride;
    extras.insert(extras.end(), e, e + stride);
  }
  Status read(const WorkFiles& files, std::uint64_t first, std::size_t n) {
    resize(n);
    LODFORGE_TRY(files.points.readAt(first * bytes, points.data(), points.size()));
    if (stride == 0) return {};
    return files.extras->readAt(first * stride, extras.data(), extras.size());
  }
  // Records [from, from + n) to record `first` of the files.
  Status write(const WorkFiles& files, std::uint64_t first, std::size_t from, std::size_t n) const {
    LODFORGE_TRY(files.points.writeAt(first * bytes, record(from), n * bytes));
    if (stride == 0) return {};
    return files.extras->writeAt(first * stride, extras.data() + from * stride, n * stride);
  }
};

// Points [from, from + out.size()) of a batch as work points, every position checked (and
// placed, with a transform), added to `stats` in order.
Status convertPoints(const std::string& input, const PartitionOptions& options,
                     const PointBatch& batch, std::size_t from, std::span<CloudPoint> out,
                     Stats& stats) {
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::size_t i = from + k;
    CloudPoint& p = out[k];
    p.position = batch.positions[i];
    if (!isFinite(p.position))
      return badInput(input, fmt::format("point {}: coordinate is not finite", batch.first + i));
    if (options.transform && !options.transform(batch.positions[i], p.position))
      return badInput(input, fmt::format("point {} ({:.10g}, {:.10g}, {:.10g}) cannot be placed "
                                         "on Earth from the coordinate system",
                                         batch.first + i, batch.positions[i].x,
                                         batch.positions[i].y, batch.positions[i].z));
    p.normal = batch.normals.empty() ? Vec3f{} : batch.normals[i];
    p.color = batch.colors.empty() ? Rgba8{} : batch.colors[i];
    p.attributes = batch.attributes.empty() ? PointAttributes{} : batch.attributes[i];
    stats.add(p);
  }
  return {};
}

// A batch as encoded work records in `records`, and its own stats (its sum is added to the
// total whole, InputRead::sum). Converted a piece at a time, so that no batch of work points
// is held: the pieces stay in the cache between conversion and encoding.
Status encodeBatch(const std::string& input, const PartitionOptions& options,
                   const PointRecordLayout& layout, const PointBatch& batch,
                   std::vector<std::byte>& records, Stats& stats) {
  constexpr std::size_t kPiece = 1024;
  stats = {};
  records.resize(batch.size() * layout.bytes());
  std::vector<CloudPoint> piece(std::min(kPiece, batch.size()));
  for (std::size_t from = 0; from < batch.size(); from += kPiece) {
    const std::span<CloudPoint> points =
        std::span(piece).first(std::min(kPiece, batch.size() - from));
    LODFORGE_TRY(convertPoints(input, options, batch, from, points, stats));
    LODFORGE_TRY(layout.encode(points, records.data() + from * layout.bytes()));
  }
  return {};
}

void addBatch(Stats& total, const Stats& batch) {
  total.count += batch.count;
  total.bounds.add(batch.bounds);
  total.sum = total.sum + batch.sum;
}

// One batch on its way through the reading pass, and what it became.
struct ReadSlot {
  PointBatch batch;
  std::vector<std::byte> records;  // encoded
  Stats stats;
};

// The reading pass' three stages over the input's batches: read (the reader is sequential),
// then converted and encoded (beside the reading and the writing), then written and counted in
// file order; up to three batches in flight. Each stage is about a third of the pass: with the
// last two on one thread, one thread waited on the other (docs/BENCHMARKS.md).
Status readBatches(const std::string& input, const PartitionOptions& options, PointReader& reader,
                   const PointRecordLayout& layout, OutputFile& out, OutputFile* extrasOut,
                   [[maybe_unused]] std::size_t stride, Stats& stats, Progress& progress) {
  constexpr std::size_t kSlots = 3;  // batches in flight (a slot is free again once written)
  std::array<ReadSlot, kSlots> slots;
  std::size_t started = 0;
  std::uint64_t handedOut = 0;  // points read so far: where a read failure is
  PipelineFailure failure;
  const auto read = [&](tbb::flow_control& control) -> ReadSlot* {
    ReadSlot& slot = slots[started % kSlots];
    Result<bool> more = failure.failed() ? Result<bool>(false) : reader.next(slot.batch);
    if (!more) failure.fail(handedOut, more.status());
    if (!more || !*more) return control.stop(), nullptr;
    ++started;
    handedOut += slot.batch.size();
    return &slot;
  };
  const auto encode = [&](ReadSlot* slot) {
    if (failure.failedBefore(slot->batch.first)) return slot;
    const Status status =
        encodeBatch(input, options, layout, slot->batch, slot->records, slot->stats);
    if (!status.ok()) failure.fail(slot->batch.first, status);
    return slot;
  };
  const auto write = [&](ReadSlot* slot) {
    if (failure.failedBefore(slot->batch.first + 1)) return;  // this batch's own failure too
    assert(!extrasOut || slot->batch.extras.size() == slot->batch.size() * stride);
    addBatch(stats, slot->stats);
    Status status = out.writeSpan(std::span<const std::byte>(slot->records));
    if (status.ok() && extrasOut)
      status = extrasOut->writeSpan(std::span<const std::byte>(slot->batch.extras));
    if (status.ok()) status = checkCancelled();
    if (!status.ok()) failure.fail(slot->batch.first, status);
    progress.advance(slot->batch.size());
  };
  tbb::parallel_pipeline(
      kSlots, tbb::make_filter<void, ReadSlot*>(tbb::filter_mode::serial_in_order, read) &
                  tbb::make_filter<ReadSlot*, ReadSlot*>(tbb::filter_mode::parallel, encode) &
                  tbb::make_filter<ReadSlot*, void>(tbb::filter_mode::serial_in_order, write));
  return failure.status();
}

// Pass 0: the input into the work files, with its bounds and centroid.
Result<InputRead> readInput(const std::string& input, const std::string& path,
                            const std::string& extrasPath, const PartitionOptions& options) {
  InputRead read;
  read.input = input;
  PointCloudInfo& info = read.info;
  PointRecordLayout& layout = read.layout;
  Result<PointReader> reader =
      PointReader::open(input, {.batchPoints = kInputBatchPoints,
                                .salvageTruncated = options.salvageTruncated,
                                .readExtras = options.carryExtras});
  if (!reader) return reader.status();
  info = reader->info();
  layout = PointRecordLayout::of(info, static_cast<bool>(options.transform), options.normals);
  const std::size_t stride = info.extras.stride;
  Result<OutputFile> out = OutputFile::create(path, std::size_t{1} << 20);
  if (!out) return out.status();
  std::optional<OutputFile> extrasOut;
  if (stride != 0) {
    Result<OutputFile> file = OutputFile::create(extrasPath, std::size_t{1} << 20);
    if (!file) return file.status();
    extrasOut.emplace(std::move(*file));
  }
  Progress progress("points: reading", info.count.value_or(0));
  Stats stats;
  LODFORGE_TRY(readBatches(input, options, *reader, layout, *out, extrasOut ? &*extrasOut : nullptr,
                           stride, stats, progress));
  progress.finish();
  read.truncation = reader->truncation();
  LODFORGE_TRY(out->commit());
  if (extrasOut) LODFORGE_TRY(extrasOut->commit());
  if (stats.count == 0) return badInput(input, "the file has no points");
  read.count = stats.count;
  read.bounds = stats.bounds;
  read.sum = stats.sum;
  return read;
}

// A file of `bytes` bytes (zeros where not yet written) that several processes then write parts
// of; `fresh`: emptied first.
Status createSizedFile(const std::string& path, std::uint64_t bytes, bool fresh = true) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | (fresh ? O_TRUNC : 0) | O_CLOEXEC, 0644);
  if (fd < 0) return ioErrorFromErrno(path, "create");
  const int sized = ::ftruncate(fd, static_cast<off_t>(bytes));
  const int error = errno;
  ::close(fd);
  if (sized != 0) {
    errno = error;
    return ioErrorFromErrno(path, "size");
  }
  return {};
}

// One streamed split of a node's range of the work file, in place: a two-ended external
// partition. Chunks are read from the front or the back, points below the plane written back
// from the front and the others from the back, only ever over records already read; at most
// about two chunks wait in memory. Rewriting cached pages instead of writing two new files
// per split made the streamed levels several times faster.
Result<std::array<PartNode, 2>> splitInPlace(const PartNode& node, const WorkFiles& files,
                                             Progress& progress) {
  const SplitPlane plane = centroidSplit(node.bounds, centroidOf(node.sum, node.count));
  constexpr std::uint64_t kChunk = std::uint64_t{1} << 14;
  const std::uint64_t begin = node.first, end = node.first + node.count;
  std::uint64_t front = begin, back = end;  // not read yet: [front, back)
  std::uint64_t low = begin, high = end;    // written: below in [begin, low), above in [high, end)
  RawRecords chunk{files.layout.bytes(), files.stride, {}, {}};
  std::array<RawRecords, 2> waiting{chunk, chunk};  // below, above
  std::array<Stats, 2> stats;
  // Writes what fits into space already read: below after `low`, above before `high`.
  const auto place = [&]() -> Status {
    RawRecords& below = waiting[0];
    const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(below.size(), front - low));
    LODFORGE_TRY(below.write(files, low, below.size() - n, n));
    below.resize(below.size() - n);
    low += n;
    RawRecords& above = waiting[1];
    const std::size_t m =
        static_cast<std::size_t>(std::min<std::uint64_t>(above.size(), high - back));
    high -= m;
    LODFORGE_TRY(above.write(files, high, above.size() - m, m));
    above.resize(above.size() - m);
    return {};
  };
  while (front < back) {
    // Read from the back when points above wait for room there, else from the front.
    const bool fromBack = waiting[1].size() > high - back;
    const std::uint64_t n = std::min(kChunk, back - front);
    LODFORGE_TRY(chunk.read(files, fromBack ? back - n : front, static_cast<std::size_t>(n)));
    (fromBack ? back : front) = fromBack ? back - n : front + n;
    for (std::size_t i = 0; i < chunk.size(); ++i) {
      const Vec3d position = files.layout.position(chunk.record(i));
      const std::size_t side = position[plane.axis] < plane.value ? 0 : 1;
      waiting[side].push(chunk, i);
      stats[side].add(position);
    }
    LODFORGE_TRY(place());
    progress.advance(n);
    LODFORGE_TRY(checkCancelled());
  }
  // Everything read: the gap [low, high) is exactly what still waits.
  LODFORGE_TRY(waiting[0].write(files, low, 0, waiting[0].size()));
  LODFORGE_TRY(waiting[1].write(files, low + waiting[0].size(), 0, waiting[1].size()));
  if (stats[0].count == 0 || stats[1].count == 0) {
    // All on one side (the node's points share the coordinate): leave it to the in-memory
    // split, which falls back to the median.
    return Error{ErrorKind::kUnsupported, "degenerate split"};
  }
  std::array<PartNode, 2> children;
  for (std::size_t side = 0; side < 2; ++side) {
    children[side].name = node.name + static_cast<char>('0' + side);
    children[side].first = side == 0 ? begin : begin + stats[0].count;
    children[side].count = stats[side].count;
    children[side].bounds = stats[side].bounds;
    children[side].sum = stats[side].sum;
  }
  return children;
}

struct Blocks {
  std::mutex mutex;
  std::vector<std::pair<std::string, PointBlock>> named;  // by split-tree name
  Status status;
};

// What every in-memory split shares: the node's extra bytes by id (its records' order as read).
struct InMemory {
  const PartitionOptions& options;
  const WorkFiles& files;  // where finished blocks go: in place, or staged from `offset` on
  std::span<const std::byte> extras;
  Blocks& blocks;
  std::uint64_t offset = 0;  // the node's first record, when staged
  std::string_view place;    // the work file the blocks end in (PointBlock::path)
};

// A finished block: handed to the sink, if any, then written back (its extra bytes gathered by
// the ids the splits and the sink moved with the points).
Status finishBlock(std::span<CloudPoint> points, std::span<std::uint32_t> ids, PointBlock& block,
                   const InMemory& shared) {
  if (shared.options.blockSink && !cancelRequested())
    LODFORGE_TRY(shared.options.blockSink(points, ids, block));
  std::vector<std::byte> scratch;
  const std::uint64_t at = block.first - shared.offset;
  LODFORGE_TRY(shared.files.writePoints(at, points, scratch));
  const std::size_t stride = shared.files.stride;
  if (stride == 0) return {};
  std::vector<std::byte> extras(points.size() * stride);
  for (std::size_t i = 0; i < ids.size(); ++i)
    std::memcpy(extras.data() + i * stride, shared.extras.data() + ids[i] * stride, stride);
  return shared.files.extras->writeAt(at * stride, extras.data(), extras.size());
}

Stats pointStats(std::span<const CloudPoint> points) {
  Stats stats;
  for (const CloudPoint& p : points) stats.add(p);
  return stats;
}

// splitPoints, and the halves' stats summed as the partition settles each point (in that
// order): a pass over every point's 64 bytes fewer a level, which was a third of the splits.
std::size_t splitWithStats(std::span<CloudPoint> points, SplitPlane plane,
                           std::span<std::uint32_t> ids, std::array<Stats, 2>& halves) {
  const std::size_t below = splitRecords(
      points, plane, ids, !ids.empty(),
      [&](const CloudPoint& p, int side) { halves[static_cast<std::size_t>(side)].add(p); });
  if (halves[0].count != below) {  // all on one side: split at the median, its stats afresh
    halves[0] = pointStats(points.first(below));
    halves[1] = pointStats(points.subspan(below));
  }
  return below;
}

// A node in memory (its records from `first` on in the work file, `stats` theirs), split
// recursively into blocks (both halves in parallel).
void splitInMemory(std::span<CloudPoint> points, std::span<std::uint32_t> ids, std::uint64_t first,
                   std::string name, const Stats& stats, const InMemory& shared) {
  if (points.size() <= shared.options.blockSize) {
    PointBlock block;
    block.name = name;
    block.path = shared.place;
    block.layout = shared.files.layout;
    block.first = first;
    block.count = points.size();
    block.bounds = stats.bounds;
    block.centroid = centroidOf(stats.sum, stats.count);
    const Status written = finishBlock(points, ids, block, shared);
    std::lock_guard lock(shared.blocks.mutex);
    if (!written.ok() && shared.blocks.status.ok()) shared.blocks.status = written;
    shared.blocks.named.emplace_back(std::move(name), std::move(block));
    return;
  }
  std::array<Stats, 2> halves;
  const std::size_t below = splitWithStats(
      points, centroidSplit(stats.bounds, centroidOf(stats.sum, stats.count)), ids, halves);
  const auto half = [&](std::span<std::uint32_t> s, bool low) {
    if (s.empty()) return s;
    return low ? s.first(below) : s.subspan(below);
  };
  tbb::task_group group;
  group.run([&] {
    splitInMemory(points.first(below), half(ids, true), first, name + "0", halves[0], shared);
  });
  splitInMemory(points.subspan(below), half(ids, false), first + below, name + "1", halves[1],
                shared);
  group.wait();
}

// What the processes of a job found splitting their share of a level: one record per node
// they split (its index in the level, whether it split, and its halves), for every process.
std::vector<std::uint64_t> encodeHalves(
    std::span<const std::optional<Result<std::array<PartNode, 2>>>> halves) {
  std::vector<std::uint64_t> out;
  for (std::size_t i = 0; i < halves.size(); ++i) {
    if (!halves[i]) continue;
    out.push_back(i);
    out.push_back(*halves[i] ? 1 : 0);
    if (!*halves[i]) continue;
    for (const PartNode& half : **halves[i]) {
      out.insert(out.end(), {half.first, half.count});
      for (const Vec3d& v : {half.bounds.min, half.bounds.max, half.sum})
        for (int k = 0; k < 3; ++k) out.push_back(std::bit_cast<std::uint64_t>(v[k]));
    }
  }
  return out;
}

Status decodeHalves(std::span<const std::uint64_t> numbers, std::span<const PartNode> level,
                    std::span<std::optional<Result<std::array<PartNode, 2>>>> halves) {
  const auto bad = [] { return Error{ErrorKind::kInternal, "the ranks' splits do not add up"}; };
  for (std::size_t at = 0; at < numbers.size();) {
    if (numbers.size() - at < 2 || numbers[at] >= level.size()) return bad();
    const std::size_t i = numbers[at];
    const bool split = numbers[at + 1] != 0;
    at += 2;
    if (halves[i]) return bad();  // two processes split the same node
    if (!split) {
      halves[i] = Result<std::array<PartNode, 2>>(Error{ErrorKind::kUnsupported, "not split"});
      continue;
    }
    if (numbers.size() - at < 22) return bad();
    std::array<PartNode, 2> both;
    for (int side = 0; side < 2; ++side) {
      PartNode& half = both[static_cast<std::size_t>(side)];
      half.name = level[i].name + static_cast<char>('0' + side);
      half.first = numbers[at++];
      half.count = numbers[at++];
      for (Vec3d* v : {&half.bounds.min, &half.bounds.max, &half.sum})
        for (int k = 0; k < 3; ++k) (*v)[k] = std::bit_cast<double>(numbers[at++]);
    }
    halves[i] = std::move(both);
  }
  return {};
}

// A job's level: each process split its share (the level's nodes to split, dealt in turn); their
// outcomes agreed and their halves exchanged, so every process has the whole level's.
Status shareLevel(std::span<const PartNode> level,
                  std::span<std::optional<Result<std::array<PartNode, 2>>>> halves,
                  const LevelShare& share) {
  Status mine = checkCancelled();
  for (const auto& half : halves)
    if (mine.ok() && half && !*half && half->error().kind != ErrorKind::kUnsupported)
      mine = half->status();
  LODFORGE_TRY(share.agree(mine));
  Result<std::vector<std::uint64_t>> all = share.gather(encodeHalves(halves));
  if (!all) return all.status();
  for (auto& half : halves) half.reset();  // every process's, this one's too, come from `all`
  return decodeHalves(*all, level, halves);
}

// Nodes too big for memory split by streamed passes, a level of the tree at a time with that
// level's nodes in parallel (each pass streams its own range); what is left, in split-tree
// order, fits in memory (or could not be split by streaming: every point on one side).
Result<std::vector<PartNode>> splitStreamedLevels(PartNode root, std::uint64_t inMemory,
                                                  const WorkFiles& files, Partition& partition,
                                                  const LevelShare& share) {
  // About one pass over every point per level: levels halve the nodes until they fit.
  int levels = 0;
  for (std::uint64_t n = root.count; n > inMemory; n = (n + 1) / 2) ++levels;
  // A job shows its own progress (LevelShare::levelDone): this bar would see one process's part.
  Progress progress(share.parts > 1 ? "" : "points: streamed splits",
                    root.count * static_cast<std::uint64_t>(levels));
  std::uint64_t splitHere = 0;
  std::vector<PartNode> level, small;
  level.push_back(std::move(root));
  while (!level.empty()) {
    std::vector<std::optional<Result<std::array<PartNode, 2>>>> halves(level.size());
    std::vector<std::uint8_t> mine(level.size(), 0);
    for (std::size_t i = 0, turn = 0; i < level.size(); ++i)
      if (level[i].count > inMemory)
        mine[i] = static_cast<int>(turn++ % static_cast<std::size_t>(share.parts)) == share.part;
    tbb::parallel_for(std::size_t{0}, level.size(), [&](std::size_t i) {
      if (mine[i] != 0 && !cancelRequested()) halves[i] = splitInPlace(level[i], files, progress);
    });
    if (share.parts > 1) {
      for (std::size_t i = 0; i < level.size(); ++i) splitHere += mine[i] != 0 ? level[i].count : 0;
      if (share.levelDone) share.levelDone(splitHere);
      LODFORGE_TRY(shareLevel(level, halves, share));
    } else {
      LODFORGE_TRY(checkCancelled());
    }
    std::vector<PartNode> next;
    for (std::size_t i = 0; i < level.size(); ++i) {
      if (halves[i] && *halves[i]) {
        ++partition.streamedPasses;
        next.push_back(std::move((**halves[i])[0]));
        next.push_back(std::move((**halves[i])[1]));
        continue;
      }
      if (halves[i] && halves[i]->error().kind != ErrorKind::kUnsupported)
        return halves[i]->status();
      small.push_back(std::move(level[i]));
    }
    level = std::move(next);
  }
  if (levels > 0) progress.finish();  // (a job's bar has no label: it shows nothing)
  std::sort(small.begin(), small.end(),
            [](const PartNode& a, const PartNode& b) { return a.name < b.name; });
  return small;
}

}  // namespace

SplitPlane centroidSplit(const Aabbd& bounds, Vec3d centroid) {
  const Vec3d size = bounds.max - bounds.min;
  int axis = 0;
  if (size.y > size[axis]) axis = 1;
  if (size.z > size[axis]) axis = 2;
  return {axis, centroid[axis]};
}

std::size_t splitPoints(std::span<CloudPoint> points, SplitPlane plane,
                        std::span<std::uint32_t> ids) {
  return splitRecords(points, plane, ids, !ids.empty());
}

// Exactly the range, by pread: a buffered reader filled a whole megabyte for every tile's
// section, and the 100 M-point contents read 38.5 GB for 5.4 GB of tiles.
Result<std::vector<CloudPoint>> readPointRecords(const std::string& path,
                                                 const PointRecordLayout& layout,
                                                 std::uint64_t first, std::uint64_t count) {
  Result<WorkFile> in = WorkFile::open(path);
  if (!in) return in.status();
  std::vector<CloudPoint> points(count);
  std::vector<std::byte> bytes(count * layout.bytes());
  LODFORGE_TRY(in->readAt(first * layout.bytes(), bytes.data(), bytes.size()));
  layout.decode(bytes.data(), points);
  return points;
}

Result<std::vector<std::byte>> readExtraRecords(const std::string& path, std::uint32_t stride,
                                                std::uint64_t first, std::uint64_t count) {
  Result<WorkFile> in = WorkFile::open(path);
  if (!in) return in.status();
  std::vector<std::byte> extras(count * stride);
  LODFORGE_TRY(in->readAt(first * stride, extras.data(), extras.size()));
  return extras;
}

Result<InputRead> readWholeInput(const std::string& input, const PartitionOptions& options) {
  assert(options.blockSize > 0 && !options.workDirectory.empty());
  return readInput(input, options.workDirectory + "/b.points", options.workDirectory + "/b.extras",
                   options);
}

Result<Partition> partitionPoints(const std::string& input, const PartitionOptions& options) {
  Result<InputRead> read = readWholeInput(input, options);
  if (!read) return read.status();
  return partitionRead(*read, options);
}

Result<InputRead> createInputFiles(const std::string& input, const PartitionOptions& options) {
  if (options.salvageTruncated)
    return Error{ErrorKind::kUnsupported,
                 fmt::format("{}: a file to salvage is read whole", input)};
  // A reader of one point's slice says whether the input can be read in slices.
  Result<PointReader> probe = PointReader::open(
      input, {.batchPoints = 1, .readExtras = options.carryExtras, .first = 0, .count = 1});
  if (!probe) return probe.status();
  PointBatch first;
  Result<bool> some = probe->next(first);
  if (!some) return some.status();
  InputRead read;
  read.input = input;
  read.info = probe->info();
  if (!*some || !read.info.count)
    return Error{ErrorKind::kUnsupported, fmt::format("{}: no point count to share", input)};
  read.layout =
      PointRecordLayout::of(read.info, static_cast<bool>(options.transform), options.normals);
  read.count = *read.info.count;
  LODFORGE_TRY(
      createSizedFile(options.workDirectory + "/b.points", read.count * read.layout.bytes()));
  const std::size_t stride = read.info.extras.stride;
  if (stride != 0)
    LODFORGE_TRY(createSizedFile(options.workDirectory + "/b.extras", read.count * stride));
  return read;
}

PointRange inputSlice(std::uint64_t points, int part, int parts) {
  assert(parts > 0 && part >= 0 && part < parts);
  const std::uint64_t batches = (points + kInputBatchPoints - 1) / kInputBatchPoints;
  const auto at = [&](int p) {
    return std::min(points, batches * static_cast<std::uint64_t>(p) /
                                static_cast<std::uint64_t>(parts) * kInputBatchPoints);
  };
  return {at(part), at(part + 1) - at(part)};
}

Result<SliceRead> readInputSlice(const std::string& input, const PartitionOptions& options,
                                 PointRange slice,
                                 const std::function<void(std::uint64_t)>& advanced) {
  SliceRead out;
  if (slice.count == 0) return out;
  Result<PointReader> reader = PointReader::open(input, {.batchPoints = kInputBatchPoints,
                                                         .readExtras = options.carryExtras,
                                                         .first = slice.first,
                                                         .count = slice.count});
  if (!reader) return reader.status();
  const PointCloudInfo& info = reader->info();
  const PointRecordLayout layout =
      PointRecordLayout::of(info, static_cast<bool>(options.transform), options.normals);
  const std::size_t stride = info.extras.stride;
  Result<WorkFile> points = WorkFile::open(options.workDirectory + "/b.points");
  if (!points) return points.status();
  std::optional<WorkFile> extras;
  if (stride != 0) {
    Result<WorkFile> opened = WorkFile::open(options.workDirectory + "/b.extras");
    if (!opened) return opened.status();
    extras.emplace(std::move(*opened));
  }
  PointBatch batch;
  std::vector<std::byte> records;
  Stats stats, batchStats;
  for (;;) {
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) break;
    const std::uint64_t at = batch.first;
    assert(batch.extras.size() == batch.size() * stride);
    LODFORGE_TRY(encodeBatch(input, options, layout, batch, records, batchStats));
    addBatch(stats, batchStats);
    out.batchSums.push_back(batchStats.sum);
    LODFORGE_TRY(points->writeAt(at * layout.bytes(), records.data(), records.size()));
    if (extras)
      LODFORGE_TRY(extras->writeAt(at * stride, batch.extras.data(), batch.extras.size()));
    if (advanced) advanced(stats.count);
    LODFORGE_TRY(checkCancelled());
  }
  if (stats.count != slice.count)
    return badInput(input,
                    fmt::format("points {} to {}: only {} read (the header counts {} points in "
                                "all)",
                                slice.first, slice.first + slice.count, stats.count,
                                reader->info().count.value_or(0)));
  out.count = stats.count;
  out.bounds = stats.bounds;
  return out;
}

void addSlices(std::span<const SliceRead> slices, InputRead& read) {
  Stats stats;
  for (const SliceRead& slice : slices) {
    stats.count += slice.count;
    stats.bounds.add(slice.bounds);
    for (const Vec3d& sum : slice.batchSums) stats.sum = stats.sum + sum;
  }
  read.count = stats.count;
  read.bounds = stats.bounds;
  read.sum = stats.sum;
}

std::uint64_t inMemoryPoints(const PartitionOptions& options, std::size_t stride) {
  // A point in memory: its record, and with extras their bytes twice (read, gathered) and an id.
  const std::uint64_t pointBytes = sizeof(CloudPoint) + (stride == 0 ? 0 : 2 * stride + 4);
  // Ids are 32-bit: no node is split in memory with more points than they count.
  return std::min<std::uint64_t>(
      std::max<std::uint64_t>(options.blockSize, options.memoryBytes / pointBytes),
      stride == 0 ? ~std::uint64_t{0} : std::numeric_limits<std::uint32_t>::max());
}

namespace {

// The work files of a read input, open.
struct OpenFiles {
  WorkFile points;
  std::optional<WorkFile> extras;
  WorkFiles view(const PointRecordLayout& layout, std::size_t stride) const {
    return WorkFiles{points, layout, extras ? &*extras : nullptr, stride};
  }
};

Result<OpenFiles> openWorkFiles(const PartitionOptions& options, std::size_t stride,
                                const std::string& stem = "b") {
  const std::string at = options.workDirectory + "/" + stem;
  Result<WorkFile> points = WorkFile::open(at + ".points");
  if (!points) return points.status();
  OpenFiles files{std::move(*points), {}};
  if (stride == 0) return files;
  Result<WorkFile> extras = WorkFile::open(at + ".extras");
  if (!extras) return extras.status();
  files.extras.emplace(std::move(*extras));
  return files;
}

// The blocks a node's split added to `blocks` (from `from` on), in name order.
std::vector<PointBlock> nodeBlocks(Blocks& blocks, std::size_t from) {
  const auto begin = blocks.named.begin() + static_cast<std::ptrdiff_t>(from);
  std::sort(begin, blocks.named.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<PointBlock> out;
  for (auto it = begin; it != blocks.named.end(); ++it) out.push_back(it->second);
  return out;
}

// The scratch files a process stages its nodes in: at least `records` records, what they hold
// kept (a resumed run places an interrupted one's staged node before it stages any).
Result<OpenFiles> scratchFiles(const InputRead& read, const PartitionOptions& options,
                               const std::string& stem, std::uint64_t records) {
  const std::string at = options.workDirectory + "/" + stem;
  LODFORGE_TRY(createSizedFile(at + ".points", records * read.layout.bytes(), false));
  const std::size_t stride = read.info.extras.stride;
  if (stride != 0) LODFORGE_TRY(createSizedFile(at + ".extras", records * stride, false));
  return openWorkFiles(options, stride, stem);
}

// Bytes [from, from + bytes) of one file to `to` of another, pieces in parallel, each copied by
// the kernel from page cache to page cache (copy_file_range: a user-space buffer took two copies;
// the copy sits between nodes, with the other threads idle).
Status copyBytes(const std::string& sourcePath, std::uint64_t from, const std::string& targetPath,
                 std::uint64_t to, std::uint64_t bytes) {
  const int in = ::open(sourcePath.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) return ioErrorFromErrno(sourcePath, "open");
  const int out = ::open(targetPath.c_str(), O_WRONLY | O_CLOEXEC);
  if (out < 0) {
    const Status error = ioErrorFromErrno(targetPath, "open");
    ::close(in);
    return error;
  }
  constexpr std::uint64_t kPiece = std::uint64_t{8} << 20;
  std::vector<Status> copied((bytes + kPiece - 1) / kPiece);
  tbb::parallel_for(std::size_t{0}, copied.size(), [&](std::size_t piece) {
    auto inAt = static_cast<off_t>(from + piece * kPiece);
    auto outAt = static_cast<off_t>(to + piece * kPiece);
    std::uint64_t left = std::min(kPiece, bytes - piece * kPiece);
    std::vector<std::byte> buffer;  // where the kernel cannot copy between the two files
    while (left > 0) {
      ssize_t n = buffer.empty() ? ::copy_file_range(in, &inAt, out, &outAt, left, 0) : -1;
      if (n < 0 && (buffer.size() > 0 || errno == ENOSYS || errno == EXDEV || errno == EOPNOTSUPP ||
                    errno == EINVAL)) {
        if (buffer.empty()) buffer.resize(static_cast<std::size_t>(left));
        n = ::pread(in, buffer.data(), static_cast<std::size_t>(left), inAt);  // never past it
        if (n > 0 && ::pwrite(out, buffer.data(), static_cast<std::size_t>(n), outAt) != n) n = -1;
        if (n > 0) inAt += n, outAt += n;
      }
      if (n <= 0) {
        copied[piece] = n == 0 ? ioError(sourcePath, "ends before the node's records")
                               : ioErrorFromErrno(targetPath, "copy into");
        return;
      }
      left -= static_cast<std::uint64_t>(n);
    }
  });
  ::close(in);
  ::close(out);
  for (const Status& status : copied) LODFORGE_TRY(status);
  return {};
}

// Records [from, from + count) of one pair of work files to `to` of another.
Status copyRecords(const WorkFiles& source, std::uint64_t from, const WorkFiles& target,
                   std::uint64_t to, std::uint64_t count) {
  const std::uint64_t bytes = source.layout.bytes();
  LODFORGE_TRY(copyBytes(source.points.path(), from * bytes, target.points.path(), to * bytes,
                         count * bytes));
  if (source.stride == 0) return {};
  return copyBytes(source.extras->path(), from * source.stride, target.extras->path(),
                   to * source.stride, count * source.stride);
}

// A node whose blocks are all in the scratch files: told, copied into place, told.
Status placeStaged(const NodeStaging& staging, const PartNode& node,
                   std::span<const PointBlock> blocks, const WorkFiles& scratch,
                   const WorkFiles& files) {
  LODFORGE_TRY(staging.staged(node, blocks));
  LODFORGE_TRY(copyRecords(scratch, 0, files, node.first, node.count));
  return staging.placed(node);
}

}  // namespace

Status placeScratchNode(const InputRead& read, const PartitionOptions& options,
                        const std::string& scratchStem, const PartitionNode& node) {
  const std::size_t stride = read.info.extras.stride;
  Result<OpenFiles> scratch = openWorkFiles(options, stride, scratchStem);
  if (!scratch) return scratch.status();
  Result<OpenFiles> files = openWorkFiles(options, stride);
  if (!files) return files.status();
  return copyRecords(scratch->view(read.layout, stride), 0, files->view(read.layout, stride),
                     node.first, node.count);
}

Result<std::vector<PartitionNode>> splitLargeNodes(const InputRead& read,
                                                   const PartitionOptions& options,
                                                   Partition& partition, const LevelShare& share) {
  partition.info = read.info;
  partition.truncation = read.truncation;
  partition.pointCount = read.count;
  partition.bounds = read.bounds;
  const std::size_t stride = partition.info.extras.stride;
  if (stride != 0) partition.extrasPath = options.workDirectory + "/b.extras";
  Result<OpenFiles> files = openWorkFiles(options, stride);
  // In a job the others are at the first level's agreement: they learn of it there.
  if (!files && share.parts > 1) LODFORGE_TRY(share.agree(files.status()));
  if (!files) return files.status();
  return splitStreamedLevels(PartNode{"b", 0, read.count, read.bounds, read.sum},
                             inMemoryPoints(options, stride), files->view(read.layout, stride),
                             partition, share);
}

Result<std::vector<PointBlock>> splitNodesInMemory(
    const InputRead& read, std::span<const PartitionNode> nodes, const PartitionOptions& options,
    const std::function<void(std::uint64_t)>& advanced, const NodeStaging* staging) {
  const std::size_t stride = read.info.extras.stride;
  Result<OpenFiles> opened = openWorkFiles(options, stride);
  if (!opened) return opened.status();
  const WorkFiles files = opened->view(read.layout, stride);
  std::uint64_t biggest = 0;
  for (const PartNode& node : nodes) biggest = std::max(biggest, node.count);
  std::optional<OpenFiles> scratch;
  if (staging) {
    Result<OpenFiles> made = scratchFiles(read, options, staging->scratchStem, biggest);
    if (!made) return made.status();
    scratch.emplace(std::move(*made));
  }
  const WorkFiles finished = scratch ? scratch->view(read.layout, stride) : files;
  Blocks blocks;
  std::uint64_t total = 0, done = 0;
  for (const PartNode& node : nodes) total += node.count;
  std::optional<Progress> progress;
  if (!advanced) progress.emplace("points: partition", total);
  // One buffer for the biggest node (growing it node by node would hold two at once).
  Records records{stride, {}, {}};
  std::vector<std::uint32_t> ids;
  records.points.reserve(static_cast<std::size_t>(biggest));
  records.extras.reserve(static_cast<std::size_t>(biggest) * stride);
  for (const PartNode& node : nodes) {
    if (stride != 0 && node.count > std::numeric_limits<std::uint32_t>::max())
      return Error{ErrorKind::kLimit,
                   fmt::format("{}: {} points share one position, more than the 2^32 that can "
                               "carry extra fields; leave them out with --attributes",
                               read.input, node.count)};
    LODFORGE_TRY(records.read(files, node.first, static_cast<std::size_t>(node.count)));
    ids.resize(stride == 0 ? 0 : records.size());
    std::iota(ids.begin(), ids.end(), 0u);
    const std::size_t before = blocks.named.size();
    // The node's stats as the reading or the streamed split summed them: no pass of its own.
    const Stats stats{node.count, node.bounds, node.sum};
    splitInMemory(records.points, ids, node.first, node.name, stats,
                  InMemory{options, finished, records.extras, blocks, scratch ? node.first : 0,
                           files.points.path()});
    if (!blocks.status.ok()) return blocks.status;
    // A block finished after a cancellation skipped the sink: such a node is never staged.
    LODFORGE_TRY(checkCancelled());
    if (staging)
      LODFORGE_TRY(placeStaged(*staging, node, nodeBlocks(blocks, before), finished, files));
    done += node.count;
    if (progress) progress->advance(node.count);
    if (advanced) advanced(done);
    LODFORGE_TRY(checkCancelled());
  }
  if (progress) progress->finish();
  std::sort(blocks.named.begin(), blocks.named.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<PointBlock> out;
  for (auto& [name, block] : blocks.named) out.push_back(std::move(block));
  return out;
}

// Then one node at a time in memory (so that only one is held), its halves in parallel.
Result<Partition> partitionRead(const InputRead& read, const PartitionOptions& options) {
  Partition partition;
  Result<std::vector<PartitionNode>> nodes = splitLargeNodes(read, options, partition);
  if (!nodes) return nodes.status();
  Result<std::vector<PointBlock>> blocks = splitNodesInMemory(read, *nodes, options);
  if (!blocks) return blocks.status();
  partition.blocks = std::move(*blocks);
  return partition;
}

}  // namespace lodforge
