#include "lodforge/tiles/point_tiles.h"

#include "lodforge/tiles/point_ranks.h"
#include "lodforge/tiles/point_resume.h"
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

#include "lodforge/core/cluster.h"
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

// One process's point run, as named steps; each step's work is kept for --resume (point_resume.h).
class PointRun {
 public:
  PointRun(const std::string& input, const std::string& output, const PointTilesOptions& options)
      : input_(input), output_(output), options_(options), work_(pointWorkDirectory(output)) {}

  Result<PointTilesStats> run() {
    LODFORGE_TRY(claimPointWorkPlace(input_, output_, options_.resume, lock_, scope_));
    Result<PointMemoryPlan> plan = planPointMemory(options_.memoryLimit, options_.blockSize);
    if (!plan) return plan.status();
    Result<std::optional<CrsToLocal>> frame = localFrame(input_, options_, stats_, hasNormals_);
    if (!frame) return frame.status();
    frame_ = std::move(*frame);
    partitionOptions_ = pointPartitionOptions(options_, *plan, frame_, work_);
    tbb::task_arena arena(plan->threads);
    LODFORGE_TRY(arena.execute([&] { return splitOrResume(); }));
    LODFORGE_TRY(arena.execute([&] { return rankOrResume(); }));
    const std::map<std::string, TileNode> nodes = tileTree(plan_.blocks);
    LODFORGE_TRY(writeTiles(nodes));
    stats_.seconds = secondsSince(start_);
    return stats_;
  }

 private:
  // The input read and split by streamed passes, or as an interrupted run left it.
  Status splitOrResume() {
    const nlohmann::json identity = pointRunIdentity(input_, options_);
    if (std::optional<SplitState> state =
            options_.resume ? loadSplitState(work_, identity) : std::nullopt) {
      Result<PointSplit> split = resumedSplit(*state, input_, partitionOptions_);
      if (!split) return split.status();
      split_ = std::move(*split);
      stats_.resumed = true;
      return {};
    }
    if (options_.resume) LODFORGE_TRY(resetPointWork(work_));  // nothing to go on from
    Result<InputRead> read = readWholeInput(input_, partitionOptions_);
    if (!read) return read.status();
    split_.read = std::move(*read);
    Result<std::vector<PartitionNode>> nodes =
        splitLargeNodes(split_.read, partitionOptions_, split_.partition);
    if (!nodes) return nodes.status();
    split_.nodes = std::move(*nodes);
    return saveSplitState(work_, identity, splitStateOf(split_));
  }

  // Every node not yet ranked split in memory and ranked, then the plan; or the plan as an
  // interrupted run left it.
  Status rankOrResume() {
    Partition& partition = split_.partition;
    stats_.nodes = split_.nodes.size();
    Result<std::optional<PointPlan>> earlier =
        stats_.resumed ? resumedPlan(work_, split_.read) : std::optional<PointPlan>();
    if (!earlier) return earlier.status();
    if (*earlier) {
      plan_ = std::move(**earlier);
      partition.blocks = plan_.partition;
      noteStats(partition, options_, stats_);
      stats_.nodesResumed = split_.nodes.size();
      return {};
    }
    if (stats_.resumed)
      LODFORGE_TRY(placeStagedNodes(work_, split_.nodes, split_.read, partitionOptions_).status());
    const std::vector<PartitionNode> todo = nodesToRank(work_, split_.nodes);
    stats_.nodesResumed = split_.nodes.size() - todo.size();
    PartitionOptions options = partitionOptions_;
    NodeRanking ranking(work_, hasNormals_, options_);
    ranking.attach(options);
    const NodeStaging staging = ranking.staging(0);
    Result<std::vector<PointBlock>> blocks =
        splitNodesInMemory(split_.read, todo, options, {}, &staging);
    if (!blocks) return blocks.status();
    Result<PointPlan> plan =
        planContents(work_, split_.read, split_.nodes, options_, partition, stats_, release_);
    if (!plan) return plan.status();
    plan_ = std::move(*plan);
    return {};
  }

  Status writeTiles(const std::map<std::string, TileNode>& nodes) {
    const PointCloudInfo& info = split_.partition.info;
    const std::string staged = work_ + "/tileset";  // kept with the work (scope_)
    Result<ContentsWritten> tiles =
        writeContents(nodes, plan_.blocks, options_,
                      {info.hasColors, info.attributes & options_.attributes, &info.extras}, staged,
                      {.resumed = stats_.resumed}, &release_);
    if (!tiles) return tiles.status();
    stats_.tiles = tiles->tiles;
    stats_.tilesResumed = tiles->kept;
    LODFORGE_TRY(writePointTilesetJson(nodes, plan_.blocks, plan_.taus,
                                       rootTransformOf(frame_, options_), options_.quantize,
                                       staged + "/tileset.json"));
    stats_.outputBytes = directoryBytes(staged);
    // Complete: replace the previous tileset, if any, by the new one.
    ScopedDirectory staging(staged);
    LODFORGE_TRY(replaceDirectory(staging, output_));
    scope_.finished = true;
    return {};
  }

  std::string input_, output_;
  const PointTilesOptions& options_;
  std::string work_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  WorkLock lock_;
  PointWorkScope scope_;
  // Destroyed before scope_ removes the work: what it was given is done first.
  SpaceRelease release_;
  PointTilesStats stats_;
  bool hasNormals_ = false;
  std::optional<CrsToLocal> frame_;
  PartitionOptions partitionOptions_;
  PointSplit split_;
  PointPlan plan_;
};

}  // namespace

Result<PointTilesStats> writePointTiles(const std::string& input,
                                        const std::string& outputDirectory,
                                        const PointTilesOptions& options) {
  if (clustered()) return writePointTilesAcrossRanks(input, outputDirectory, options);
  return PointRun(input, outputDirectory, options).run();
}

}  // namespace lodforge
