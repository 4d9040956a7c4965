#include "lodforge/points/build.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/points/cloud_file.h"
#include "lodforge/points/partition.h"

namespace lodforge {

namespace fs = std::filesystem;

namespace {

Result<std::vector<CloudPoint>> loadBlock(const PointBlock& block) {
  return readPointRecords(block.path, block.layout, block.first, block.count);
}

// The automatic tolerance: the median over sample blocks of the one that keeps `share` of a
// block's points as Part II.
Result<double> pickTolerance(const Partition& partition, const PointsBuildOptions& options,
                             bool hasNormals) {
  const std::size_t samples = std::min<std::size_t>(8, partition.blocks.size());
  std::vector<double> tolerances(samples);
  std::vector<Status> failures(samples);
  tbb::parallel_for(std::size_t{0}, samples, [&](std::size_t s) {
    const PointBlock& block = partition.blocks[s * partition.blocks.size() / samples];
    Result<std::vector<CloudPoint>> points = loadBlock(block);
    if (!points) {
      failures[s] = points.status();
      return;
    }
    const std::vector<ClusterNode> tree =
        clusterBlock(*points, block.centroid, hasNormals, options.cluster);
    const auto resident = static_cast<std::size_t>(
        std::max(1.0, options.residentShare * static_cast<double>(block.count)));
    tolerances[s] = toleranceForResident(tree, resident);
  });
  for (const Status& f : failures) LODFORGE_TRY(f);
  std::nth_element(tolerances.begin(),
                   tolerances.begin() + static_cast<std::ptrdiff_t>(samples / 2), tolerances.end());
  return tolerances[samples / 2];
}

// What a block costs while it is built, per point: its records, the tree (two nodes per point)
// and its ranges, the k-d tree and local copies, and the cut's copy of the tree (measured
// ≈ 280 bytes; rounded up).
constexpr std::uint64_t kBlockBytesPerPoint = 320;
// Buffers of the streamed passes and the package writer.
constexpr std::uint64_t kBufferBytes = std::uint64_t{12} << 20;

}  // namespace

Result<PointMemoryPlan> planPointMemory(std::uint64_t memoryLimit, std::uint64_t blockSize) {
  PointMemoryPlan plan;
  plan.threads = tbb::this_task_arena::max_concurrency();
  plan.partitionBytes = PartitionOptions{}.memoryBytes;
  if (memoryLimit == 0) return plan;
  const std::uint64_t base = currentRssBytes() + kBufferBytes;
  const std::uint64_t block = blockSize * kBlockBytesPerPoint;
  const std::uint64_t least = base + block + 2 * blockSize * sizeof(CloudPoint);
  if (memoryLimit < least)
    return Error{ErrorKind::kLimit,
                 fmt::format("--memory-limit {} is too small for blocks of {} points: at least {} "
                             "(or smaller blocks with --block-size)",
                             formatBytes(memoryLimit), blockSize, formatBytes(least))};
  const std::uint64_t available = memoryLimit - base;
  plan.threads = static_cast<int>(std::clamp<std::uint64_t>(
      available / 2 / block, 1, static_cast<std::uint64_t>(plan.threads)));
  plan.partitionBytes = available - static_cast<std::uint64_t>(plan.threads) * block;
  return plan;
}

namespace {

void countPartition(const Partition& partition, PointsBuildStats& stats) {
  stats.points = partition.pointCount;
  stats.blocks = partition.blocks.size();
  stats.streamedPasses = partition.streamedPasses;
  stats.truncation = partition.truncation;
  stats.warnings = partition.info.warnings;
  stats.minBlock = stats.points;
  for (const PointBlock& b : partition.blocks) {
    stats.minBlock = std::min(stats.minBlock, b.count);
    stats.maxBlock = std::max(stats.maxBlock, b.count);
  }
}

// One block: its clustering tree, the cut at `tolerance` (Part II in `cut`, Part III to its
// segment file) and its table entry.
Status buildBlock(const PointBlock& block, std::size_t b, bool hasNormals, double tolerance,
                  const PointsBuildOptions& options, const std::string& segmentDirectory,
                  std::uint64_t buildId, LodCut& cut, CloudBlock& entry) {
  Result<std::vector<CloudPoint>> points = loadBlock(block);
  if (!points) return points.status();
  const std::vector<ClusterNode> tree =
      clusterBlock(*points, block.centroid, hasNormals, options.cluster);
  cut = cutTree(tree, static_cast<float>(tolerance));
  entry.bounds = block.bounds;
  entry.origin = block.centroid;
  entry.pointCount = block.count;
  entry.residentCount = static_cast<std::uint32_t>(cut.resident.size());
  entry.segmentCount = static_cast<std::uint32_t>(cut.segment.size());
  entry.maxError = tree.front().error;
  for (const ClusterNode& n : cut.resident)
    entry.residentError = std::max(entry.residentError, n.error);
  return writeSegmentFile(segmentDirectory + "/" + segmentFileName(b), buildId, b, cut.segment);
}

// The blocks' table and, per block, where its Part II lies in the resident work file.
struct BuiltBlocks {
  std::vector<CloudBlock> table;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> residentAt;  // first record, count
};

// Blocks in parallel; Part II goes to a work file in completion order, placed at the end.
Result<BuiltBlocks> buildBlocks(const Partition& partition, const PointsBuildOptions& options,
                                double tolerance, const std::string& segmentDirectory,
                                std::uint64_t buildId, const std::string& residentPath,
                                tbb::task_arena& arena, PointsBuildStats& stats) {
  const bool hasNormals = partition.info.hasNormals;
  BuiltBlocks built;
  built.table.resize(partition.blocks.size());
  built.residentAt.resize(built.table.size());
  Result<OutputFile> residentFile = OutputFile::create(residentPath);
  if (!residentFile) return residentFile.status();
  std::mutex mutex;
  std::uint64_t residentWritten = 0;
  Status failure;
  Progress progress("points: blocks", stats.points);
  arena.execute([&] {
    tbb::parallel_for(std::size_t{0}, built.table.size(), [&](std::size_t b) {
      if (cancelRequested()) return;
      const PointBlock& block = partition.blocks[b];
      LodCut cut;
      Status status = buildBlock(block, b, hasNormals, tolerance, options, segmentDirectory,
                                 buildId, cut, built.table[b]);
      std::lock_guard lock(mutex);
      if (status.ok()) status = residentFile->writeSpan(std::span<const ClusterNode>(cut.resident));
      if (!status.ok()) {
        if (failure.ok()) failure = status;
        return;
      }
      built.residentAt[b] = {residentWritten, static_cast<std::uint32_t>(cut.resident.size())};
      residentWritten += cut.resident.size();
      stats.residentNodes += cut.resident.size();
      stats.segmentNodes += cut.segment.size();
      stats.droppedNodes += cut.dropped;
      progress.advance(block.count);
    });
  });
  LODFORGE_TRY(failure);
  LODFORGE_TRY(checkCancelled());
  progress.finish();
  LODFORGE_TRY(residentFile->commit());
  return built;
}

// Part II in block order, each block's records read back from the work file as the package is
// written (holding all of Part II would grow with the input).
ResidentSource residentReader(const std::string& residentPath, BuiltBlocks& built) {
  std::uint64_t first = 0;
  for (CloudBlock& entry : built.table) {
    entry.residentFirst = first;
    first += entry.residentCount;
  }
  return [residentPath, &built](std::size_t b) -> Result<std::vector<ClusterNode>> {
    std::ifstream in(residentPath, std::ios::binary);
    std::vector<ClusterNode> part(built.residentAt[b].second);
    in.seekg(static_cast<std::streamoff>(built.residentAt[b].first * sizeof(ClusterNode)));
    in.read(reinterpret_cast<char*>(part.data()),
            static_cast<std::streamsize>(part.size() * sizeof(ClusterNode)));
    if (!in && !part.empty()) return ioError(residentPath, "work file is shorter than expected");
    return part;
  };
}

CloudHeader packageHeader(const Partition& partition, const PointsBuildStats& stats,
                          std::uint64_t buildId) {
  CloudHeader header{};
  header.flags = (partition.info.hasNormals ? kCloudInputNormals : 0u) |
                 (partition.info.hasColors ? kCloudInputColors : 0u);
  header.buildId = buildId;
  header.pointCount = stats.points;
  header.segmentCount = stats.segmentNodes;
  header.droppedCount = stats.droppedNodes;
  header.tolerance = stats.tolerance;
  header.bounds = partition.bounds;
  return header;
}

}  // namespace

Result<PointsBuildStats> buildPointCloud(const std::string& input, const std::string& output,
                                         const PointsBuildOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PointsBuildStats stats;
  LODFORGE_TRY(claimPointPackageOutput(input, output));
  // A work directory of our own: a fresh name unless the caller chose one.
  ScopedDirectory work(options.workDirectory.empty() ? temporaryPathFor(output + ".work")
                                                     : options.workDirectory);
  std::error_code error;
  fs::create_directories(work.path, error);
  if (error) return ioError(work.path, error.message());

  // The partition into blocks (§4.1 of the points paper), split in memory as far as it allows.
  Result<PointMemoryPlan> plan = planPointMemory(options.memoryLimit, options.blockSize);
  if (!plan) return plan.status();
  PartitionOptions partitionOptions;
  partitionOptions.blockSize = options.blockSize;
  partitionOptions.workDirectory = work.path;
  partitionOptions.salvageTruncated = options.salvageTruncated;
  partitionOptions.memoryBytes = options.splitBytes > 0 ? options.splitBytes : plan->partitionBytes;
  stats.threads = plan->threads;
  Result<Partition> partition = partitionPoints(input, partitionOptions);
  if (!partition) return partition.status();
  stats.partitionSeconds = secondsSince(start);
  countPartition(*partition, stats);
  stats.estimatedNormals = !partition->info.hasNormals;

  // Blocks (the sampled ones too) are built by as many threads as the memory plan allows.
  tbb::task_arena arena(plan->threads);
  stats.tolerance = options.tolerance;
  if (stats.tolerance <= 0) {
    Result<double> picked = arena.execute(
        [&] { return pickTolerance(*partition, options, partition->info.hasNormals); });
    if (!picked) return picked.status();
    stats.tolerance = *picked;
  }

  // Segment files go straight into a staging directory renamed when the package is complete.
  const std::string segments = segmentDirectoryFor(output);
  ScopedDirectory staging(temporaryPathFor(segments));
  fs::create_directories(staging.path, error);
  if (error) return ioError(staging.path, error.message());
  const std::uint64_t buildId =
      std::random_device{}() ^ (std::uint64_t{std::random_device{}()} << 32);
  const std::string residentPath = work.path + "/resident";
  Result<BuiltBlocks> built = buildBlocks(*partition, options, stats.tolerance, staging.path,
                                          buildId, residentPath, arena, stats);
  if (!built) return built.status();

  // The segment directory first, then the package that names its build: a crash between the
  // two leaves a package that refuses the new segments (other build id), never a mix.
  const ResidentSource residentOf = residentReader(residentPath, *built);
  LODFORGE_TRY(replaceDirectory(staging, segments));
  LODFORGE_TRY(writeCloudFile(output, packageHeader(*partition, stats, buildId),
                              partition->info.crs, built->table, residentOf));
  const Result<std::uint64_t> packageBytes = fileSize(output);
  stats.outputBytes = directoryBytes(segments) + (packageBytes ? *packageBytes : 0);
  stats.seconds = secondsSince(start);
  return stats;
}

}  // namespace lodforge
