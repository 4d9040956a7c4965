#include "lodforge/points/partition.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"

namespace lodforge {

namespace {

// A node of the partition while it is being split: records [first, first + count) of the work
// file (every node's, split in place).
struct PartNode {
  std::string name;  // path in the split tree: "b", "b0", "b01", ... (depth-first order)
  std::uint64_t first = 0;
  std::uint64_t count = 0;
  Aabbd bounds;
  Vec3d sum;  // of positions, for the centroid
};

struct Stats {
  std::uint64_t count = 0;
  Aabbd bounds;
  Vec3d sum;
  void add(const CloudPoint& p) {
    ++count;
    bounds.add(p.position);
    sum = sum + p.position;
  }
};

Vec3d centroidOf(const Vec3d& sum, std::uint64_t count) {
  return sum * (1.0 / static_cast<double>(std::max<std::uint64_t>(1, count)));
}

constexpr std::uint64_t at(std::uint64_t record) {
  return record * sizeof(CloudPoint);
}

// Pass 0: the input into one work file, with its bounds and centroid.
Result<PartNode> readInput(const std::string& input, const std::string& path,
                           const PartitionOptions& options, Partition& partition) {
  PointCloudInfo& info = partition.info;
  Result<PointReader> reader = PointReader::open(input, 1 << 16, options.salvageTruncated);
  if (!reader) return reader.status();
  info = reader->info();
  Result<OutputFile> out = OutputFile::create(path, std::size_t{1} << 20);
  if (!out) return out.status();
  Progress progress("points: reading", info.count.value_or(0));
  PointBatch batch;
  // Each batch is written (a kernel copy into new pages, as costly as the parsing) while the
  // next is converted: two buffers, one write in flight, awaited on every way out.
  std::array<std::vector<CloudPoint>, 2> records;
  Status written;
  tbb::task_group writing;
  struct Await {
    tbb::task_group& group;
    ~Await() { group.wait(); }
  } await{writing};
  Stats stats;
  for (std::size_t turn = 0;; turn ^= 1) {
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) break;
    std::vector<CloudPoint>& mine = records[turn];
    mine.resize(batch.size());
    for (std::size_t i = 0; i < batch.size(); ++i) {
      CloudPoint& p = mine[i];
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
    writing.wait();
    LODFORGE_TRY(written);
    writing.run([&out, &written, &mine] {
      try {  // nothing may escape into the waiting destructor
        written = out->writeSpan(std::span<const CloudPoint>(mine));
      } catch (const std::exception& e) {
        written = ioError(out->path(), e.what());
      }
    });
    progress.advance(batch.size());
    LODFORGE_TRY(checkCancelled());
  }
  writing.wait();
  LODFORGE_TRY(written);
  progress.finish();
  partition.truncation = reader->truncation();
  LODFORGE_TRY(out->commit());
  if (stats.count == 0) return badInput(input, "the file has no points");
  return PartNode{"b", 0, stats.count, stats.bounds, stats.sum};
}

// One streamed split of a node's range of the work file, in place: a two-ended external
// partition. Chunks are read from the front or the back, points below the plane written back
// from the front and the others from the back, only ever over records already read; at most
// about two chunks wait in memory. Rewriting cached pages instead of writing two new files
// per split made the streamed levels several times faster.
Result<std::array<PartNode, 2>> splitInPlace(const PartNode& node, const WorkFile& file,
                                             Progress& progress) {
  const SplitPlane plane = centroidSplit(node.bounds, centroidOf(node.sum, node.count));
  constexpr std::uint64_t kChunk = std::uint64_t{1} << 14;
  const std::uint64_t begin = node.first, end = node.first + node.count;
  std::uint64_t front = begin, back = end;  // not read yet: [front, back)
  std::uint64_t low = begin, high = end;    // written: below in [begin, low), above in [high, end)
  std::vector<CloudPoint> chunk;
  std::array<std::vector<CloudPoint>, 2> waiting;  // below, above
  std::array<Stats, 2> stats;
  // Writes what fits into space already read: below after `low`, above before `high`.
  const auto place = [&]() -> Status {
    std::vector<CloudPoint>& below = waiting[0];
    const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(below.size(), front - low));
    LODFORGE_TRY(file.writeAt(at(low), below.data() + below.size() - n, n * sizeof(CloudPoint)));
    below.resize(below.size() - n);
    low += n;
    std::vector<CloudPoint>& above = waiting[1];
    const std::size_t m =
        static_cast<std::size_t>(std::min<std::uint64_t>(above.size(), high - back));
    high -= m;
    LODFORGE_TRY(file.writeAt(at(high), above.data() + above.size() - m, m * sizeof(CloudPoint)));
    above.resize(above.size() - m);
    return {};
  };
  while (front < back) {
    // Read from the back when points above wait for room there, else from the front.
    const bool fromBack = waiting[1].size() > high - back;
    const std::uint64_t n = std::min(kChunk, back - front);
    chunk.resize(static_cast<std::size_t>(n));
    LODFORGE_TRY(file.readAt(at(fromBack ? back - n : front), chunk.data(), at(n)));
    (fromBack ? back : front) = fromBack ? back - n : front + n;
    for (const CloudPoint& p : chunk) {
      const std::size_t side = p.position[plane.axis] < plane.value ? 0 : 1;
      waiting[side].push_back(p);
      stats[side].add(p);
    }
    LODFORGE_TRY(place());
    progress.advance(n);
    LODFORGE_TRY(checkCancelled());
  }
  // Everything read: the gap [low, high) is exactly what still waits.
  LODFORGE_TRY(file.writeAt(at(low), waiting[0].data(), at(waiting[0].size())));
  LODFORGE_TRY(file.writeAt(at(low + waiting[0].size()), waiting[1].data(), at(waiting[1].size())));
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

// A node in memory (its records from `first` on in the work file), split recursively into
// blocks (both halves in parallel); each block is handed to the sink, if any, then written
// back in place.
void splitInMemory(std::span<CloudPoint> points, std::uint64_t first, std::string name,
                   const PartitionOptions& options, const WorkFile& file, Blocks& blocks) {
  Stats stats;
  for (const CloudPoint& p : points) stats.add(p);
  if (points.size() <= options.blockSize) {
    PointBlock block;
    block.name = name;
    block.path = file.path();
    block.first = first;
    block.count = points.size();
    block.bounds = stats.bounds;
    block.centroid = centroidOf(stats.sum, stats.count);
    Status written;
    if (options.blockSink && !cancelRequested()) written = options.blockSink(points, block);
    if (written.ok()) written = file.writeAt(at(first), points.data(), points.size_bytes());
    std::lock_guard lock(blocks.mutex);
    if (!written.ok() && blocks.status.ok()) blocks.status = written;
    blocks.named.emplace_back(std::move(name), std::move(block));
    return;
  }
  const std::size_t below =
      splitPoints(points, centroidSplit(stats.bounds, centroidOf(stats.sum, stats.count)));
  tbb::task_group group;
  group.run([&] { splitInMemory(points.first(below), first, name + "0", options, file, blocks); });
  splitInMemory(points.subspan(below), first + below, name + "1", options, file, blocks);
  group.wait();
}

// Nodes too big for memory split by streamed passes, a level of the tree at a time with that
// level's nodes in parallel (each pass streams its own range); what is left, in split-tree
// order, fits in memory (or could not be split by streaming: every point on one side).
Result<std::vector<PartNode>> splitStreamedLevels(PartNode root, std::uint64_t inMemory,
                                                  const WorkFile& file, Partition& partition) {
  // About one pass over every point per level: levels halve the nodes until they fit.
  int levels = 0;
  for (std::uint64_t n = root.count; n > inMemory; n = (n + 1) / 2) ++levels;
  Progress progress("points: streamed splits", root.count * static_cast<std::uint64_t>(levels));
  std::vector<PartNode> level, small;
  level.push_back(std::move(root));
  while (!level.empty()) {
    std::vector<std::optional<Result<std::array<PartNode, 2>>>> halves(level.size());
    tbb::parallel_for(std::size_t{0}, level.size(), [&](std::size_t i) {
      if (level[i].count > inMemory && !cancelRequested())
        halves[i] = splitInPlace(level[i], file, progress);
    });
    LODFORGE_TRY(checkCancelled());
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
  if (levels > 0) progress.finish();
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

std::size_t splitPoints(std::span<CloudPoint> points, SplitPlane plane) {
  const auto middle = std::partition(points.begin(), points.end(), [&](const CloudPoint& p) {
    return p.position[plane.axis] < plane.value;
  });
  std::size_t below = static_cast<std::size_t>(middle - points.begin());
  if ((below == 0 || below == points.size()) && points.size() >= 2) {
    below = points.size() / 2;
    std::nth_element(points.begin(), points.begin() + static_cast<std::ptrdiff_t>(below),
                     points.end(), [&](const CloudPoint& a, const CloudPoint& b) {
                       return a.position[plane.axis] < b.position[plane.axis];
                     });
  }
  return below;
}

Result<std::vector<CloudPoint>> readPointRecords(const std::string& path, std::uint64_t first,
                                                 std::uint64_t count) {
  Result<ByteSource> in = ByteSource::openFile(path);
  if (!in) return in.status();
  std::vector<CloudPoint> points(count);
  if (!in->skip(first * sizeof(CloudPoint)) ||
      !in->read(points.data(), points.size() * sizeof(CloudPoint)))
    return ioError(path, "work file is shorter than expected");
  return points;
}

Result<Partition> partitionPoints(const std::string& input, const PartitionOptions& options) {
  assert(options.blockSize > 0 && !options.workDirectory.empty());
  Partition partition;
  const std::string path = options.workDirectory + "/b.points";
  Result<PartNode> root = readInput(input, path, options, partition);
  if (!root) return root.status();
  partition.pointCount = root->count;
  partition.bounds = root->bounds;
  Result<WorkFile> file = WorkFile::open(path);
  if (!file) return file.status();
  const std::uint64_t inMemory =
      std::max<std::uint64_t>(options.blockSize, options.memoryBytes / sizeof(CloudPoint));
  Result<std::vector<PartNode>> nodes =
      splitStreamedLevels(std::move(*root), inMemory, *file, partition);
  if (!nodes) return nodes.status();
  // Then one node at a time in memory (so that only one is held), its halves in parallel.
  Blocks blocks;
  Progress progress("points: partition", partition.pointCount);
  // One buffer for the biggest node (growing it node by node would hold two at once).
  std::vector<CloudPoint> points;
  std::uint64_t biggest = 0;
  for (const PartNode& node : *nodes) biggest = std::max(biggest, node.count);
  points.reserve(static_cast<std::size_t>(biggest));
  for (const PartNode& node : *nodes) {
    points.resize(static_cast<std::size_t>(node.count));
    LODFORGE_TRY(file->readAt(at(node.first), points.data(), points.size() * sizeof(CloudPoint)));
    splitInMemory(points, node.first, node.name, options, *file, blocks);
    if (!blocks.status.ok()) return blocks.status;
    progress.advance(node.count);
    LODFORGE_TRY(checkCancelled());
  }
  progress.finish();
  std::sort(blocks.named.begin(), blocks.named.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [name, block] : blocks.named) {
    partition.blocks.push_back(std::move(block));
  }
  return partition;
}

}  // namespace lodforge
