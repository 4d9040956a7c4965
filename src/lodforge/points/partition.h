// Block partition of a point cloud (points paper §4.1, "Data partition"): split at the centroid
// along the longest axis until every block holds at most `blockSize` points. Out-of-core: the
// input is streamed once into a work file, nodes larger than the memory allowance are split by
// streamed passes over their range of it (in place), smaller ones are split in memory; every
// block ends as a contiguous range of CloudPoint records in that file.
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cstdint>
#include <functional>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/io/points/point_reader.h"
#include "lodforge/points/point_record.h"

namespace lodforge {

struct PointBlock {
  std::string name;  // its path in the split tree: "b", then "0" (lower side) or "1" per split
  std::string path;  // the work file that holds its CloudPoint records, from `first` on
  PointRecordLayout layout;  // of those records
  std::uint64_t first = 0;
  std::uint64_t count = 0;
  Aabbd bounds;
  Vec3d centroid;
};

struct PartitionOptions {
  std::uint64_t blockSize = 50'000;  // at most this many points per block
  // Points held in memory at once while splitting (bytes); nodes above it are split by streamed
  // passes over their files.
  std::uint64_t memoryBytes = std::uint64_t{512} << 20;
  std::string workDirectory;      // must exist
  bool salvageTruncated = false;  // read a PLY cut short up to its last whole point
  // Carry the input's extra fields (LAS extra bytes, other PLY properties) in a second work file;
  // without, they are not read.
  bool carryExtras = false;
  // The block sink sets normals (a cloud without any gets them by PCA): kFloat or kBytes keep
  // them in the work file even when the input has none.
  RecordNormals normals = RecordNormals::kInput;
  // Applied to every point as it is read (one thread): e.g. a CRS to a local frame. False
  // refuses the point.
  std::function<bool(Vec3d, Vec3d&)> transform;
  // Called with each finished block's points while they are in memory, from several threads
  // at once; it may reorder them, and they are written back to the work file as it left them.
  // With extra fields it gets one id per point and must reorder them with the points (so the
  // extras can follow); without, the ids are empty.
  std::function<Status(std::span<CloudPoint>, std::span<std::uint32_t> ids, PointBlock&)> blockSink;
};

struct Partition {
  PointCloudInfo info;
  // The work file of the points' extra bytes (info.extras.stride each) when they have any:
  // record i belongs to record i of the blocks' file.
  std::string extrasPath;
  std::vector<PointBlock> blocks;  // depth-first, lower side first
  std::uint64_t pointCount = 0;
  Aabbd bounds;
  int streamedPasses = 0;                 // splits done by streaming a node's file
  std::optional<std::string> truncation;  // where a salvaged input was cut short
};

// The position where a node splits and the axis (the longest of its bounds).
struct SplitPlane {
  int axis = 0;
  double value = 0;
};
SplitPlane centroidSplit(const Aabbd& bounds, Vec3d centroid);

// Reorders `points` so that those below the plane come first and returns how many they are. When
// every point falls on one side (coincident coordinates), splits at the median along the axis
// instead, so both sides are non-empty whenever there are two points or more. `ids`, if given
// (one per point), is reordered with them.
std::size_t splitPoints(std::span<CloudPoint> points, SplitPlane plane,
                        std::span<std::uint32_t> ids = {});

// `values` rearranged so that value k is the one that was at order[k] (a permutation); nothing
// for empty values. Points and their ids follow a sort or a selection this way.
template <class T>
void applyOrder(std::span<const std::uint32_t> order, std::span<T> values) {
  if (values.empty()) return;
  assert(order.size() == values.size());
  const std::vector<T> was(values.begin(), values.end());
  for (std::size_t k = 0; k < order.size(); ++k) values[k] = was[order[k]];
}

// Hoare's partition of `points` by `below(i)`, as std::partition leaves it, moving the ids too;
// where the first point not below is. Its swaps, the k-th point not below from the left with
// the k-th below from the right while they have not crossed, are made a block of each end at a
// time with those points' offsets gathered first (BlockQuicksort's scheme, Edelkamp and Weiss
// 2016): no branch on a point's side, which the scan mispredicted about every other point.
template <class Point, class Below, class Settled>
std::size_t hoarePartition(std::span<Point> points, std::span<std::uint32_t> ids, Below below,
                           Settled&& settled) {
  const auto swap = [&](std::size_t i, std::size_t j) {
    std::swap(points[i], points[j]);
    if (!ids.empty()) std::swap(ids[i], ids[j]);
  };
  constexpr std::size_t kBlock = 64;
  // Offsets of the points to swap: from the left block's start, and from the right block's end.
  std::array<std::uint8_t, kBlock> aboveAt;
  std::array<std::uint8_t, kBlock> belowAt;
  std::size_t l = 0, r = points.size(), ahead = 0, behind = 0, nextAbove = 0, nextBelow = 0;
  while (r - l > 2 * kBlock) {  // blocks [l, l + kBlock) and [r - kBlock, r) apart
    if (ahead == 0) {
      nextAbove = 0;
      for (std::size_t k = 0; k < kBlock; ++k) {
        aboveAt[ahead] = static_cast<std::uint8_t>(k);
        ahead += static_cast<std::size_t>(!below(l + k));
      }
    }
    if (behind == 0) {
      nextBelow = 0;
      for (std::size_t k = 0; k < kBlock; ++k) {
        belowAt[behind] = static_cast<std::uint8_t>(k);
        behind += static_cast<std::size_t>(below(r - 1 - k));
      }
    }
    const std::size_t pairs = std::min(ahead, behind);
    for (std::size_t k = 0; k < pairs; ++k)
      swap(l + aboveAt[nextAbove + k], r - 1 - belowAt[nextBelow + k]);
    ahead -= pairs, behind -= pairs, nextAbove += pairs, nextBelow += pairs;
    if (ahead == 0) {
      for (std::size_t k = 0; k < kBlock; ++k) settled(points[l + k], 0);
      l += kBlock;
    }
    if (behind == 0) {
      for (std::size_t k = 0; k < kBlock; ++k) settled(points[r - 1 - k], 1);
      r -= kBlock;
    }
  }
  // Hoare's own loop from where its ends would be: each block's next point on the wrong side.
  std::size_t i = ahead > 0 ? l + aboveAt[nextAbove] : l;
  std::size_t j = behind > 0 ? r - belowAt[nextBelow] : r;
  for (std::size_t k = l; k < i; ++k) settled(points[k], 0);
  for (std::size_t k = j; k < r; ++k) settled(points[k], 1);
  while (true) {
    while (i < j && below(i)) settled(points[i++], 0);
    while (i < j && !below(j - 1)) settled(points[--j], 1);
    if (i >= j) return i;
    swap(i, j - 1);
    settled(points[i++], 0);
    settled(points[--j], 1);
  }
}

// The same for any record with a `position` (the clustering splits a compact copy). `flatStays`:
// when every point has the axis' coordinate, any half will do and nothing moves (splitPoints
// sets it when it has ids). Its swaps depend only on the positions, so the order it leaves is
// the same for every record type. `settled(point, side)` sees each point once, where the
// partition puts it (0 below, 1 above), unless every point is on one side (then it sees them
// all on that side and the median split follows).
struct SettledNowhere {
  template <class Point>
  void operator()(const Point&, int) const {}
};
template <class Point, class Settled = SettledNowhere>
std::size_t splitRecords(std::span<Point> points, SplitPlane plane, std::span<std::uint32_t> ids,
                         bool flatStays, Settled settled = {}) {
  assert(ids.empty() || ids.size() == points.size());
  const auto below = [&](std::size_t i) { return points[i].position[plane.axis] < plane.value; };
  const std::size_t i = hoarePartition(points, ids, below, settled);
  if ((i != 0 && i != points.size()) || points.size() < 2) return i;
  const std::size_t count = points.size() / 2;
  const auto half = static_cast<std::ptrdiff_t>(count);
  const auto byAxis = [&](const Point& a, const Point& b) {
    return a.position[plane.axis] < b.position[plane.axis];
  };
  if (flatStays) {
    const auto [least, most] = std::minmax_element(points.begin(), points.end(), byAxis);
    if (least->position[plane.axis] == most->position[plane.axis]) return count;
  }
  if (ids.empty()) {
    std::nth_element(points.begin(), points.begin() + half, points.end(), byAxis);
    return count;
  }
  // Through an index (rare: rounding put the centroid outside), then the points and their ids
  // moved together: the same order as selecting on the points themselves.
  std::vector<std::uint32_t> order(points.size());
  std::iota(order.begin(), order.end(), 0u);
  std::nth_element(order.begin(), order.begin() + half, order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return byAxis(points[a], points[b]); });
  applyOrder(order, points);
  applyOrder(order, ids);
  return count;
}

// Records [first, first + count) of a work file of CloudPoints (a block's, say).
Result<std::vector<CloudPoint>> readPointRecords(const std::string& path,
                                                 const PointRecordLayout& layout,
                                                 std::uint64_t first, std::uint64_t count);
// The same records' extra bytes from the extras work file.
Result<std::vector<std::byte>> readExtraRecords(const std::string& path, std::uint32_t stride,
                                                std::uint64_t first, std::uint64_t count);

Result<Partition> partitionPoints(const std::string& input, const PartitionOptions& options);

// The input in the work files after the first pass (read by one process, or in slices by the
// processes of a job): what partitionRead goes on from.
struct InputRead {
  std::string input;  // its path, for messages
  PointCloudInfo info;
  PointRecordLayout layout;
  std::uint64_t count = 0;
  Aabbd bounds;
  // Of the positions: each batch's sum (batchPoints points from the first) added in batch order,
  // the same sum however the batches were shared out.
  Vec3d sum;
  std::optional<std::string> truncation;
};

// A job's first pass (point_ranks.h): process 0 makes the work files at their full size
// (createInputFiles: kUnsupported for an input not read in slices: text, ascii PLY, a LAZ file
// without a chunk table, a file to salvage); each process reads its slice of whole batches into
// them (inputSlice, readInputSlice); every process adds up all the slices in order (addSlices)
// before the partition's job steps below.
constexpr std::size_t kInputBatchPoints = std::size_t{1} << 16;
struct SliceRead {
  std::uint64_t count = 0;
  Aabbd bounds;
  std::vector<Vec3d> batchSums;  // a batch's sum of positions each, in order
};
Result<InputRead> createInputFiles(const std::string& input, const PartitionOptions& options);
struct PointRange {
  std::uint64_t first = 0, count = 0;
};
PointRange inputSlice(std::uint64_t points, int part, int parts);
// `advanced` (if any) is told the points read so far after each batch.
Result<SliceRead> readInputSlice(const std::string& input, const PartitionOptions& options,
                                 PointRange slice,
                                 const std::function<void(std::uint64_t)>& advanced = {});
// `read` (from createInputFiles) with every slice's count, bounds and sum, in slice order.
void addSlices(std::span<const SliceRead> slices, InputRead& read);
Result<Partition> partitionRead(const InputRead& read, const PartitionOptions& options);
// The input read by one process (partitionPoints' first pass).
Result<InputRead> readWholeInput(const std::string& input, const PartitionOptions& options);

// partitionRead in two steps, for a job: the processes split the nodes too big for memory by
// streamed passes (splitLargeNodes: the nodes left, each split in memory next, in name order;
// `partition` gets all but the blocks); each process then splits its share of those nodes in
// memory, one at a time, each block handed to the sink and written back in place
// (splitNodesInMemory: its blocks in name order; `advanced`, if any, told the points done after
// each node instead of a progress bar).
struct PartitionNode {
  std::string name;         // path in the split tree: "b", "b0", "b01", ... (depth-first order)
  std::uint64_t first = 0;  // records [first, first + count) of the work files
  std::uint64_t count = 0;
  Aabbd bounds;
  Vec3d sum;  // of positions, for the centroid
};
// In a job every process splits its share of each level (the nodes to split, dealt in turn),
// and `agree` (every process's outcome) and `gather` (every process's numbers, in process order)
// give each the whole level: the same nodes come out on every process.
// Every process must give the same PartitionOptions::memoryBytes: the nodes to split and their
// turns follow from it. `levelDone`, if any, is told the points this process has split so far
// after each level (for the job's progress).
struct LevelShare {
  int part = 0, parts = 1;
  std::function<Status(const Status&)> agree;
  std::function<Result<std::vector<std::uint64_t>>(std::span<const std::uint64_t>)> gather;
  std::function<void(std::uint64_t)> levelDone;
};
// The most points a node split in memory may have (`stride`: extra bytes a point): larger ones
// are split by streamed passes.
std::uint64_t inMemoryPoints(const PartitionOptions& options, std::size_t stride);
Result<std::vector<PartitionNode>> splitLargeNodes(const InputRead& read,
                                                   const PartitionOptions& options,
                                                   Partition& partition,
                                                   const LevelShare& share = {});
// With `staging`, each node's finished blocks go first to scratch files in the work directory
// (`scratchStem` + ".points" and ".extras", from record 0); `staged` is told the node and its
// blocks once they are all there, then they are copied into the node's place and `placed` is
// told. So the node of an interrupted run is either untouched in place (split it again) or whole
// in the scratch files with its summary staged (placeScratchNode copies it again), never half
// overwritten with nothing whole to mend it from.
struct NodeStaging {
  std::string scratchStem;
  std::function<Status(const PartitionNode&, std::span<const PointBlock>)> staged;
  std::function<Status(const PartitionNode&)> placed;
};
Result<std::vector<PointBlock>> splitNodesInMemory(
    const InputRead& read, std::span<const PartitionNode> nodes, const PartitionOptions& options,
    const std::function<void(std::uint64_t)>& advanced = {}, const NodeStaging* staging = nullptr);
// A staged node's records, from the scratch files of `scratchStem`, into its place.
Status placeScratchNode(const InputRead& read, const PartitionOptions& options,
                        const std::string& scratchStem, const PartitionNode& node);

}  // namespace lodforge
