#include "lodforge/points/partition.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <optional>

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"

namespace lodforge {

namespace {

// A node of the partition while it is being split: its points in a file, or in memory.
struct PartNode {
  std::string name;  // path in the split tree: "b", "b0", "b01", ... (depth-first order)
  std::string path;
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

Status writePoints(const std::string& path, std::span<const CloudPoint> points) {
  Result<OutputFile> out = OutputFile::create(path, std::size_t{1} << 20);
  if (!out) return out.status();
  LODFORGE_TRY(out->writeSpan(points));
  return out->commit();
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
  std::vector<CloudPoint> records;
  Stats stats;
  while (true) {
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) break;
    records.resize(batch.size());
    for (std::size_t i = 0; i < batch.size(); ++i) {
      CloudPoint& p = records[i];
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
    LODFORGE_TRY(out->writeSpan(std::span<const CloudPoint>(records)));
    progress.advance(batch.size());
    LODFORGE_TRY(checkCancelled());
  }
  progress.finish();
  partition.truncation = reader->truncation();
  LODFORGE_TRY(out->commit());
  if (stats.count == 0) return badInput(input, "the file has no points");
  return PartNode{"b", path, stats.count, stats.bounds, stats.sum};
}

// One streamed split: the node's file into two, lower side first.
Result<std::array<PartNode, 2>> splitStreamed(const PartNode& node, const std::string& work,
                                              Progress& progress) {
  const SplitPlane plane = centroidSplit(node.bounds, centroidOf(node.sum, node.count));
  std::array<PartNode, 2> children;
  std::array<Stats, 2> stats;
  std::array<std::optional<OutputFile>, 2> outs;
  for (std::size_t side = 0; side < 2; ++side) {
    children[side].name = node.name + static_cast<char>('0' + side);
    children[side].path = work + "/" + children[side].name + ".points";
    Result<OutputFile> out = OutputFile::create(children[side].path, std::size_t{1} << 20);
    if (!out) return out.status();
    outs[side].emplace(std::move(*out));
  }
  Result<ByteSource> in = ByteSource::openFile(node.path);
  if (!in) return in.status();
  std::vector<CloudPoint> batch(1 << 14);
  std::array<std::vector<CloudPoint>, 2> sides;
  for (std::uint64_t done = 0; done < node.count;) {
    const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(batch.size(), node.count - done));
    if (!in->read(batch.data(), n * sizeof(CloudPoint)))
      return ioError(node.path, "work file is shorter than expected");
    sides[0].clear();
    sides[1].clear();
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t side = batch[i].position[plane.axis] < plane.value ? 0 : 1;
      sides[side].push_back(batch[i]);
      stats[side].add(batch[i]);
    }
    for (std::size_t side = 0; side < 2; ++side)
      LODFORGE_TRY(outs[side]->writeSpan(std::span<const CloudPoint>(sides[side])));
    done += n;
    progress.advance(n);
    LODFORGE_TRY(checkCancelled());
  }
  if (stats[0].count == 0 || stats[1].count == 0) {
    // All on one side (the node's points share the coordinate): leave it to the in-memory
    // split, which falls back to the median.
    return Error{ErrorKind::kUnsupported, "degenerate split"};
  }
  for (std::size_t side = 0; side < 2; ++side) {
    LODFORGE_TRY(outs[side]->commit());
    children[side].count = stats[side].count;
    children[side].bounds = stats[side].bounds;
    children[side].sum = stats[side].sum;
  }
  std::error_code ignored;
  std::filesystem::remove(node.path, ignored);
  return children;
}

struct Blocks {
  std::mutex mutex;
  std::vector<std::pair<std::string, PointBlock>> named;  // by split-tree name
  Status status;
};

// A node in memory, split recursively into blocks (both halves in parallel); each block to its
// file, or to the sink.
void splitInMemory(std::span<CloudPoint> points, std::string name, const PartitionOptions& options,
                   Blocks& blocks) {
  Stats stats;
  for (const CloudPoint& p : points) stats.add(p);
  if (points.size() <= options.blockSize) {
    PointBlock block;
    block.name = name;
    block.count = points.size();
    block.bounds = stats.bounds;
    block.centroid = centroidOf(stats.sum, stats.count);
    Status written;
    if (options.blockSink) {
      written = cancelRequested() ? Status{} : options.blockSink(points, block);
    } else {
      block.path = options.workDirectory + "/" + name + ".block";
      written = writePoints(block.path, points);
    }
    std::lock_guard lock(blocks.mutex);
    if (!written.ok() && blocks.status.ok()) blocks.status = written;
    blocks.named.emplace_back(std::move(name), std::move(block));
    return;
  }
  const std::size_t below =
      splitPoints(points, centroidSplit(stats.bounds, centroidOf(stats.sum, stats.count)));
  tbb::task_group group;
  group.run([&] { splitInMemory(points.first(below), name + "0", options, blocks); });
  splitInMemory(points.subspan(below), name + "1", options, blocks);
  group.wait();
}

// Nodes too big for memory split by streamed passes, a level of the tree at a time with that
// level's nodes in parallel (each pass streams its own files); what is left, in split-tree
// order, fits in memory (or could not be split by streaming: every point on one side).
Result<std::vector<PartNode>> splitStreamedLevels(PartNode root, std::uint64_t inMemory,
                                                  const std::string& work, Partition& partition) {
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
        halves[i] = splitStreamed(level[i], work, progress);
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
  Result<PartNode> root = readInput(input, options.workDirectory + "/b.points", options, partition);
  if (!root) return root.status();
  partition.pointCount = root->count;
  partition.bounds = root->bounds;
  const std::uint64_t inMemory =
      std::max<std::uint64_t>(options.blockSize, options.memoryBytes / sizeof(CloudPoint));
  Result<std::vector<PartNode>> nodes =
      splitStreamedLevels(std::move(*root), inMemory, options.workDirectory, partition);
  if (!nodes) return nodes.status();
  // Then one node at a time in memory (so that only one is held), its halves in parallel.
  Blocks blocks;
  Progress progress("points: partition", partition.pointCount);
  for (const PartNode& node : *nodes) {
    Result<std::vector<CloudPoint>> points = readPointRecords(node.path, 0, node.count);
    if (!points) return points.status();
    std::error_code ignored;
    std::filesystem::remove(node.path, ignored);
    splitInMemory(*points, node.name, options, blocks);
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
