// What lets `lodforge tiles --resume` go on from an interrupted point run (docs/tiles.md,
// "Resume"): in the point work directory, the split state (the input read and split down to the
// nodes that fit in memory, and what from), a summary per node split in memory and ranked (its
// blocks), and the plan (tolerances, points per depth). Each is written whole and atomically, and
// a resumed run takes the state only when it was made from the same input and options.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "lodforge/core/space_release.h"
#include "lodforge/core/status.h"
#include "lodforge/points/partition.h"
#include "lodforge/tiles/point_steps.h"
#include "lodforge/tiles/point_tiles.h"

namespace lodforge {

// Everything the split and the tiles depend on: the input (path, size, modification time) and
// the options.
nlohmann::json pointRunIdentity(const std::string& input, const PointTilesOptions& options);

// The input read and its large nodes split by streamed passes: the totals and the nodes left
// to split in memory, in name order.
struct SplitState {
  std::uint64_t count = 0;
  Aabbd bounds;
  Vec3d sum;
  std::optional<std::string> truncation;
  std::vector<PartitionNode> nodes;
};
// The input in the work files and split down to the nodes that fit in memory.
struct PointSplit {
  InputRead read;
  Partition partition;               // all but the blocks
  std::vector<PartitionNode> nodes;  // to split in memory, in name order
};
SplitState splitStateOf(const PointSplit& split);
// The split an earlier run left, with the input's header read again (`options` as the
// partition's, for the records' layout).
Result<PointSplit> resumedSplit(const SplitState& state, const std::string& input,
                                const PartitionOptions& options);
// Written once the streamed splits are done, with the work files' sizes; from then on the work
// is kept for --resume.
Status saveSplitState(const std::string& workDirectory, const nlohmann::json& identity,
                      const SplitState& state);
// An earlier run's state, when intact, made with `identity` and its work files still of the
// sizes it recorded (else the run starts over).
std::optional<SplitState> loadSplitState(const std::string& workDirectory,
                                         const nlohmann::json& identity);
// Whether `workDirectory` holds a split state (the work is worth keeping).
bool pointWorkKept(const std::string& workDirectory);

// A ranked block as its node's summary lists it (its records in `path` from `first` on).
struct RankedBlock {
  PointBlock block;
  float rootError = 0, leastError = 0;
};
// Written when every block of the node is ranked and staged (`scratchStem`: where); renamed
// as done (markNodeDone) once they are in place: that name's presence means done.
Status writeRankedNode(const std::string& workDirectory, const std::string& nodeName,
                       const std::string& scratchStem, std::span<const RankedBlock> blocks);
Status markNodeDone(const std::string& workDirectory, const std::string& nodeName);
// Per node, whether it is done (its records in place).
std::vector<bool> rankedNodesDone(const std::string& workDirectory,
                                  std::span<const PartitionNode> nodes);
// Every node's blocks, in name order; `path` and `layout` are the ranked records'.
Result<std::vector<RankedBlock>> readRankedNodes(const std::string& workDirectory,
                                                 std::span<const PartitionNode> nodes,
                                                 const std::string& path,
                                                 const PointRecordLayout& layout);

// Ranks each block as the partition makes it (rankBlock) and stages each node (NodeStaging):
// once all of a node's blocks are in the scratch files, its summary is written as staged (with
// the scratch files' name); once they are in place, it is renamed as done (a durable step:
// checkpointReached("pointnode"); "pointstaged" between the two, "pointblock" after each block
// ranked).
class NodeRanking {
 public:
  NodeRanking(std::string workDirectory, bool hasNormals, const PointTilesOptions& options)
      : work_(std::move(workDirectory)), hasNormals_(hasNormals), options_(options) {}
  // `partition` with the sink that ranks the blocks.
  void attach(PartitionOptions& partition);
  // The staging of a process (`rank`: its own scratch files).
  NodeStaging staging(int rank);

 private:
  std::string work_;
  bool hasNormals_;
  const PointTilesOptions& options_;
  std::mutex mutex_;
  std::map<std::string, std::array<float, 2>> errors_;  // a ranked block's root and least error
};
// Puts in place every node an interrupted run had staged but not placed, and marks it done;
// how many. Before any process stages again (the scratch files are reused).
Result<std::uint64_t> placeStagedNodes(const std::string& workDirectory,
                                       std::span<const PartitionNode> nodes, const InputRead& read,
                                       const PartitionOptions& options);
// The nodes not done yet (rankedNodesDone; a fresh run's: all), in name order.
std::vector<PartitionNode> nodesToRank(const std::string& workDirectory,
                                       std::span<const PartitionNode> nodes);

// A block's tiles as ranked into the work directory (`layout` of its records; `extras`: they
// carry extra bytes).
BlockTiles rankedBlockTiles(const std::string& workDirectory, const std::string& name,
                            const PointRecordLayout& layout, bool extras);

// The contents' plan: the tolerances and each block (name, points, first record, bounds,
// points per depth, root error).
Status writePointPlan(const std::string& workDirectory, std::span<const float> taus,
                      std::span<const BlockTiles> blocks, std::span<const PointBlock> partition);
struct PointPlan {
  std::vector<float> taus;
  std::vector<BlockTiles> blocks;     // name, first, bounds, counts, rootError
  std::vector<PointBlock> partition;  // name, count, bounds
};
// The plan as written; nothing when there is none (an error when it is damaged).
Result<std::optional<PointPlan>> readPointPlan(const std::string& workDirectory);
// Once every node is ranked (one process, or rank 0 of a job): the blocks from the node
// summaries, the tolerances and each block's points per depth, written as the plan; then the
// keys and the scratch files, which nothing needs any more, are given to `release` to remove.
// The partition's blocks and the stats are filled in.
Result<PointPlan> planContents(const std::string& workDirectory, const InputRead& read,
                               std::span<const PartitionNode> nodes,
                               const PointTilesOptions& options, Partition& partition,
                               PointTilesStats& stats, SpaceRelease& release);
// The plan of an earlier run (then its blocks' paths as rankedBlockTiles'), if there is one.
Result<std::optional<PointPlan>> resumedPlan(const std::string& workDirectory,
                                             const InputRead& read);

}  // namespace lodforge
