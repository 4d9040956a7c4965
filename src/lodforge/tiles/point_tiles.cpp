#include "lodforge/tiles/point_tiles.h"

#include "lodforge/tiles/point_ranks.h"
#include "lodforge/tiles/point_steps.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cassert>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/points/build.h"
#include "lodforge/points/partition.h"
#include "lodforge/tiles/point_attributes.h"
#include "lodforge/tiles/tileset.h"
#include "lodforge/tiles/tileset_output.h"

namespace lodforge {

namespace fs = std::filesystem;

float pointTileError(const ClusterNode& node, float reach) {
  return std::max({node.error, node.radius, reach});
}

std::vector<float> representativeReach(std::span<const ClusterNode> tree,
                                       std::span<const std::uint32_t> reps,
                                       std::span<const CloudPoint> points) {
  assert(reps.size() == tree.size());
  std::vector<float> reach(tree.size(), 0.0f);
  for (std::size_t i = tree.size(); i-- > 0;) {
    const ClusterNode& node = tree[i];
    if (node.leaf()) continue;
    double farthest = 0;
    for (std::uint32_t c = node.firstChild; c < node.firstChild + 2; ++c)
      farthest = std::max(farthest, length(points[reps[c]].position - points[reps[i]].position) +
                                        static_cast<double>(reach[c]));
    // Rounded up: a bound must not lose its last bit to the float.
    float up = static_cast<float>(farthest);
    if (static_cast<double>(up) < farthest)
      up = std::nextafter(up, std::numeric_limits<float>::max());
    reach[i] = up;
  }
  return reach;
}

std::vector<std::uint32_t> clusterRepresentatives(std::span<const ClusterNode> tree,
                                                  std::span<const CloudPoint> points,
                                                  std::span<const std::uint32_t> firstPoint,
                                                  Vec3d origin) {
  std::vector<std::uint32_t> reps(tree.size());
  for (std::size_t i = tree.size(); i-- > 0;) {
    const ClusterNode& node = tree[i];
    if (node.leaf()) {
      reps[i] = firstPoint[i];
      continue;
    }
    const Vec3d c = origin + toDouble(node.position);
    const std::uint32_t a = reps[node.firstChild], b = reps[node.firstChild + 1];
    reps[i] = length(points[a].position - c) <= length(points[b].position - c) ? a : b;
  }
  return reps;
}

// A stable LSD radix sort of the inverted bits (a non-negative float's bits order like the float),
// three passes of 11 bits: what sorting (inverted bits << 32 | index) gave, at a third of the time.
std::vector<std::uint32_t> descendingKeyOrder(std::span<const float> key) {
  constexpr int kBits = 11;
  constexpr std::uint32_t kBuckets = 1u << kBits;
  std::vector<std::uint32_t> order(key.size()), next(key.size()), inverted(key.size());
  for (std::uint32_t i = 0; i < key.size(); ++i) {
    assert(!(key[i] < 0));  // −0 was made +0 (pointKeys)
    inverted[i] = ~std::bit_cast<std::uint32_t>(key[i]);
    order[i] = i;
  }
  for (int shift = 0; shift < 32; shift += kBits) {
    std::array<std::uint32_t, kBuckets + 1> start{};
    for (const std::uint32_t v : inverted) ++start[((v >> shift) & (kBuckets - 1)) + 1];
    for (std::uint32_t b = 0; b < kBuckets; ++b) start[b + 1] += start[b];
    for (const std::uint32_t i : order) next[start[(inverted[i] >> shift) & (kBuckets - 1)]++] = i;
    order.swap(next);
  }
  return order;
}

std::vector<float> pointKeys(std::span<const ClusterNode> tree,
                             std::span<const std::uint32_t> reps) {
  std::vector<float> key(tree.empty() ? 0 : (tree.size() + 1) / 2);
  if (tree.empty()) return key;
  key[reps[0]] = std::numeric_limits<float>::infinity();
  for (std::size_t t = 0; t < tree.size(); ++t) {
    const ClusterNode& node = tree[t];
    if (node.leaf()) continue;
    // Tile errors are non-negative; + 0 turns a −0 into +0 so that the keys' bits sort.
    assert(node.error >= 0);
    for (std::uint32_t c = node.firstChild; c < node.firstChild + 2; ++c)
      if (reps[c] != reps[t]) key[reps[c]] = node.error + 0.0f;
  }
  return key;
}

namespace {

// The blocks of the partition, each ranked as the partition makes it, while its points are in
// memory (no block files written and read back), as many at once as the memory plan allows.
struct RankedPartition {
  Partition partition;
  std::vector<BlockTiles> blocks;  // in the partition's block order
};

Result<RankedPartition> partitionAndRank(const std::string& input, const PointTilesOptions& options,
                                         const PointMemoryPlan& plan,
                                         const std::optional<CrsToLocal>& frame, bool hasNormals,
                                         const std::string& workDirectory) {
  PartitionOptions partitionOptions = pointPartitionOptions(options, plan, frame, workDirectory);
  std::mutex ranked;
  std::map<std::string, BlockTiles> byName;
  partitionOptions.blockSink = [&](std::span<CloudPoint> points, std::span<std::uint32_t> ids,
                                   PointBlock& block) {
    BlockTiles tiles;
    LODFORGE_TRY(rankBlock(points, ids, block, hasNormals, options, workDirectory, tiles));
    std::lock_guard lock(ranked);
    byName[block.name] = std::move(tiles);
    return Status{};
  };
  tbb::task_arena arena(plan.threads);
  Result<Partition> partition =
      arena.execute([&] { return partitionPoints(input, partitionOptions); });
  if (!partition) return partition.status();
  RankedPartition out{std::move(*partition), {}};
  for (const PointBlock& b : out.partition.blocks) {
    out.blocks.push_back(std::move(byName.at(b.name)));
    out.blocks.back().extrasPath = out.partition.extrasPath;
  }
  return out;
}

}  // namespace

Result<PointTilesStats> writePointTiles(const std::string& input,
                                        const std::string& outputDirectory,
                                        const PointTilesOptions& options) {
  if (clustered()) return writePointTilesAcrossRanks(input, outputDirectory, options);
  const auto start = std::chrono::steady_clock::now();
  PointTilesStats stats;
  WorkLock lock;
  ScopedDirectory scope;
  LODFORGE_TRY(claimPointWorkPlace(input, outputDirectory, lock, scope));
  Result<PointMemoryPlan> plan = planPointMemory(options.memoryLimit, options.blockSize);
  if (!plan) return plan.status();
  const std::string work = pointWorkDirectory(outputDirectory);
  ScopedDirectory staging(work + "/tileset");

  bool hasNormals = false;
  Result<std::optional<CrsToLocal>> frame = localFrame(input, options, stats, hasNormals);
  if (!frame) return frame.status();
  Result<RankedPartition> ranked =
      partitionAndRank(input, options, *plan, *frame, hasNormals, work);
  if (!ranked) return ranked.status();
  const Partition& partition = ranked->partition;
  std::vector<BlockTiles>& blocks = ranked->blocks;
  noteStats(partition, options, stats);
  Result<std::vector<float>> taus = toleranceSchedule(partition, blocks, options, stats.depth);
  if (!taus) return taus.status();
  LODFORGE_TRY(countLevels(partition, *taus, blocks));

  const std::map<std::string, TileNode> nodes = tileTree(blocks);
  Result<std::uint64_t> tiles =
      writeContents(nodes, blocks, options,
                    {partition.info.hasColors, partition.info.attributes & options.attributes,
                     &partition.info.extras},
                    staging.path);
  if (!tiles) return tiles.status();
  stats.tiles = *tiles;
  LODFORGE_TRY(writePointTilesetJson(nodes, blocks, *taus, rootTransformOf(*frame, options),
                                     options.quantize, staging.path + "/tileset.json"));
  stats.outputBytes = directoryBytes(staging.path);

  // Complete: replace the previous tileset, if any, by the new one.
  LODFORGE_TRY(replaceDirectory(staging, outputDirectory));
  stats.seconds = secondsSince(start);
  return stats;
}

}  // namespace lodforge
