#include "lodforge/tiles/point_ranks.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>

#include <tbb/task_arena.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/cluster.h"
#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/tiles/point_resume.h"
#include "lodforge/tiles/point_steps.h"
#include "lodforge/tiles/tileset.h"

namespace lodforge {

namespace {

// A rank's share of the nodes (dealLargestFirst by their points), in name order as given.
std::vector<PartitionNode> nodeShare(std::span<const PartitionNode> nodes, int rank, int ranks) {
  std::vector<std::uint64_t> work;
  for (const PartitionNode& node : nodes) work.push_back(node.count + 1);
  const std::vector<int> owner = dealLargestFirst(work, ranks);
  std::vector<PartitionNode> out;
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (owner[i] == rank) out.push_back(nodes[i]);
  return out;
}

// A slice's count, bounds and batch sums as numbers for gatherAcrossRanks, and back.
std::vector<std::uint64_t> encodeSlice(const SliceRead& slice) {
  std::vector<std::uint64_t> out = {slice.count};
  for (const Vec3d& corner : {slice.bounds.min, slice.bounds.max})
    for (int k = 0; k < 3; ++k) out.push_back(std::bit_cast<std::uint64_t>(corner[k]));
  out.push_back(slice.batchSums.size());
  for (const Vec3d& sum : slice.batchSums)
    for (int k = 0; k < 3; ++k) out.push_back(std::bit_cast<std::uint64_t>(sum[k]));
  return out;
}

Result<std::vector<SliceRead>> decodeSlices(std::span<const std::uint64_t> numbers, int expected) {
  std::vector<SliceRead> slices;
  std::size_t at = 0;
  const auto number = [&]() -> double { return std::bit_cast<double>(numbers[at++]); };
  while (at < numbers.size()) {
    if (numbers.size() - at < 8) break;
    SliceRead& slice = slices.emplace_back();
    slice.count = numbers[at++];
    for (Vec3d* corner : {&slice.bounds.min, &slice.bounds.max})
      for (int k = 0; k < 3; ++k) (*corner)[k] = number();
    const std::uint64_t sums = numbers[at++];
    if (numbers.size() - at < 3 * sums) break;
    for (std::uint64_t i = 0; i < sums; ++i) {
      Vec3d& sum = slice.batchSums.emplace_back();
      for (int k = 0; k < 3; ++k) sum[k] = number();
    }
  }
  if (at != numbers.size() || slices.size() != static_cast<std::size_t>(expected))
    return Error{ErrorKind::kInternal, "the ranks' slices of the input do not add up"};
  return slices;
}

class RankedPoints {
 public:
  RankedPoints(const std::string& input, const std::string& output,
               const PointTilesOptions& options)
      : input_(input),
        output_(output),
        options_(options),
        lead_(clusterRank() == 0),
        work_(pointWorkDirectory(output)) {}

  Result<PointTilesStats> run() {
    Result<PointMemoryPlan> plan = planPointMemory(options_.memoryLimit, options_.blockSize);
    LODFORGE_TRY(agreeAcrossRanks(plan.status()));
    plan_ = *plan;
    LODFORGE_TRY(agreeOnPartitionMemory());
    LODFORGE_TRY(agreeAcrossRanks(lead_ ? claimOnLead() : Status{}));
    Result<std::uint64_t> resumed = sumAcrossRanks(state_ ? 1 : 0);  // rank 0's decision
    if (!resumed) return resumed.status();
    stats_.resumed = *resumed > 0;
    setActivityDirectory(work_ + "/ranks");
    LODFORGE_TRY(agreeAcrossRanks(readHeader()));
    if (stats_.resumed) {
      LODFORGE_TRY(agreeAcrossRanks(takeSplitState()));
    } else {
      LODFORGE_TRY(readAndSplit());
    }
    LODFORGE_TRY(rankOrResume());
    stats_.rankingSeconds = secondsSince(start_);
    recordStage("partition and ranking");
    LODFORGE_TRY(writeShare());
    recordStage("contents");
    LODFORGE_TRY(agreeAcrossRanks(lead_ ? finishOnLead() : Status{}));
    stats_.ranks = clusterSize();
    stats_.rankStages = rankStages();
    stats_.seconds = secondsSince(start_);
    return stats_;
  }

 private:
  std::string stagingPath() const { return work_ + "/tileset"; }

  // Every rank splits with the least allowance of all (each rank's plan counts its own
  // footprint): the nodes to split, and whose turn each is, follow from it.
  Status agreeOnPartitionMemory() {
    Result<std::vector<std::uint64_t>> all =
        gatherAcrossRanks(std::span<const std::uint64_t>(&plan_.partitionBytes, 1));
    if (!all) return all.status();
    plan_.partitionBytes = *std::min_element(all->begin(), all->end());
    return {};
  }

  // Rank 0 claims the output and the work place, and takes an interrupted job's split input
  // when resuming (its work goes otherwise).
  Status claimOnLead() {
    LODFORGE_TRY(claimPointWorkPlace(input_, output_, options_.resume, lock_, scope_));
    if (!options_.resume) return {};
    state_ = loadSplitState(work_, pointRunIdentity(input_, options_));
    return state_ ? Status{} : resetPointWork(work_);
  }

  // The input read into the work files and its large nodes split, then recorded (rank 0).
  Status readAndSplit() {
    Result<bool> sliced = readTogether();
    if (!sliced) return sliced.status();
    stats_.readInSlices = *sliced;
    stats_.readSeconds = secondsSince(start_);
    recordStage("input");
    LODFORGE_TRY(splitTogether());
    stats_.partitionSeconds = secondsSince(start_);
    return agreeAcrossRanks(
        lead_ ? saveSplitState(work_, pointRunIdentity(input_, options_), splitStateOf(split_))
              : Status{});
  }

  // Every rank: the split input as the interrupted job left it (rank 0 has checked it).
  Status takeSplitState() {
    if (!lead_) state_ = loadSplitState(work_, pointRunIdentity(input_, options_));
    if (!state_) return ioError(work_, "the interrupted job's state cannot be read");
    Result<PointSplit> split =
        resumedSplit(*state_, input_, pointPartitionOptions(options_, plan_, frame_, work_));
    if (!split) return split.status();
    split_ = std::move(*split);
    return {};
  }

  // Every node not yet ranked split and ranked by the ranks, then rank 0's plan; or the plan
  // as an interrupted job left it. Every rank ends with the plan.
  Status rankOrResume() {
    stats_.nodes = split_.nodes.size();
    Result<std::optional<PointPlan>> earlier =
        lead_ && stats_.resumed ? resumedPlan(work_, split_.read) : std::optional<PointPlan>();
    LODFORGE_TRY(agreeAcrossRanks(earlier.status()));
    Result<std::uint64_t> planned = sumAcrossRanks(lead_ && *earlier ? 1 : 0);
    if (!planned) return planned.status();
    if (*planned == 0) {
      LODFORGE_TRY(agreeAcrossRanks(lead_ && stats_.resumed ? placeStagedOnLead() : Status{}));
      std::vector<std::uint64_t> done;  // rank 0's view
      if (lead_)
        for (const bool d : rankedNodesDone(work_, split_.nodes)) done.push_back(d ? 1 : 0);
      Result<std::vector<PartitionNode>> todo = nodesToRankOnLead(done);
      if (!todo) return todo.status();
      stats_.nodesResumed = split_.nodes.size() - todo->size();
      LODFORGE_TRY(rankTogether(*todo));
      LODFORGE_TRY(agreeAcrossRanks(lead_ ? planOnLead() : Status{}));
    } else {
      stats_.nodesResumed = split_.nodes.size();
      stats_.rankPoints.assign(static_cast<std::size_t>(clusterSize()), 0);
      if (lead_) {
        contents_ = std::move(**earlier);
        split_.partition.blocks = contents_.partition;
        noteStats(split_.partition, options_, stats_);
      }
    }
    return agreeAcrossRanks(lead_ ? Status{} : readPlan());
  }

  // Rank 0: the nodes the interrupted job had staged but not placed, in place.
  Status placeStagedOnLead() {
    return placeStagedNodes(work_, split_.nodes, split_.read,
                            pointPartitionOptions(options_, plan_, frame_, work_))
        .status();
  }

  // The nodes still to rank as rank 0 sees them (`done`, one flag a node, empty on the other
  // ranks), for every rank.
  Result<std::vector<PartitionNode>> nodesToRankOnLead(std::span<const std::uint64_t> done) {
    Result<std::vector<std::uint64_t>> all = gatherAcrossRanks(done);  // rank 0's alone
    if (!all) return all.status();
    if (all->size() != split_.nodes.size())
      return Error{ErrorKind::kInternal, "the ranks do not agree on the partition's nodes"};
    std::vector<PartitionNode> todo;
    for (std::size_t i = 0; i < all->size(); ++i)
      if ((*all)[i] == 0) todo.push_back(split_.nodes[i]);
    return todo;
  }

  // Every rank reads the header: the frame and the records' layout the partition will use.
  Status readHeader() {
    Result<std::optional<CrsToLocal>> frame = localFrame(input_, options_, stats_, hasNormals_);
    if (!frame) return frame.status();
    frame_ = std::move(*frame);
    Result<PointReader> reader =
        PointReader::open(input_, {.batchPoints = 1,
                                   .salvageTruncated = options_.salvageTruncated,
                                   .readExtras = (options_.attributes & kAttrExtras) != 0});
    if (!reader) return reader.status();
    info_ = reader->info();
    const PartitionOptions partition = pointPartitionOptions(options_, plan_, frame_, work_);
    layout_ = PointRecordLayout::of(info_, frame_.has_value(), partition.normals);
    return {};
  }

  // The input into the work files: read by every rank, a slice of whole batches each, where its
  // format allows (an uncompressed LAS, a binary PLY), else by rank 0 alone; true when sliced.
  Result<bool> readTogether() {
    const PartitionOptions options = pointPartitionOptions(options_, plan_, frame_, work_);
    Result<InputRead> files = lead_ ? createInputFiles(input_, options) : InputRead{};
    const bool alone = !files && files.status().kind() == ErrorKind::kUnsupported;
    LODFORGE_TRY(agreeAcrossRanks(files || alone ? Status{} : files.status()));
    // Rank 0's count to all (+ 1: 0 says the input is read by rank 0 alone).
    Result<std::uint64_t> count = sumAcrossRanks(lead_ && files ? files->count + 1 : 0);
    if (!count) return count.status();
    if (*count == 0) {
      reportActivity(lead_ ? "reading the input" : "waiting for rank 0 to read the input");
      LODFORGE_TRY(agreeAcrossRanks(lead_ ? readOnLead(options) : Status{}));
      // Rank 0's totals to every rank, as one slice.
      Result<std::vector<std::uint64_t>> totals = gatherAcrossRanks(
          lead_ ? encodeSlice(SliceRead{split_.read.count, split_.read.bounds, {split_.read.sum}})
                : std::vector<std::uint64_t>{});
      if (!totals) return totals.status();
      LODFORGE_TRY(addSlicesFrom(*totals, 1));
      return false;
    }
    if (lead_) split_.read = std::move(*files);
    reportActivity("reading its slice of the input");
    Result<SliceRead> mine = SliceRead{};
    {
      const JobProgress progress(fmt::format("points: reading, {} ranks", clusterSize()), "read",
                                 *count - 1);
      mine = readInputSlice(input_, options, inputSlice(*count - 1, clusterRank(), clusterSize()),
                            [](std::uint64_t done) { reportProgress("read", done); });
      LODFORGE_TRY(agreeAcrossRanks(mine.status()));
    }
    Result<std::vector<std::uint64_t>> slices = gatherAcrossRanks(encodeSlice(*mine));
    if (!slices) return slices.status();
    LODFORGE_TRY(addSlicesFrom(*slices, clusterSize()));
    return true;
  }

  // Every rank: the input's totals from the slices gathered, and what it knows of the input.
  Status addSlicesFrom(std::span<const std::uint64_t> numbers, int slices) {
    Result<std::vector<SliceRead>> decoded = decodeSlices(numbers, slices);
    if (!decoded) return decoded.status();
    addSlices(*decoded, split_.read);
    split_.read.input = input_;
    split_.read.info = info_;
    split_.read.layout = layout_;
    return {};
  }

  // The points the streamed levels go over: the input once per level above the allowance.
  std::uint64_t streamedPoints(const PartitionOptions& options) const {
    const std::uint64_t inMemory = inMemoryPoints(options, info_.extras.stride);
    std::uint64_t total = 0;
    for (std::uint64_t n = split_.read.count; n > inMemory; n = (n + 1) / 2)
      total += split_.read.count;
    return total;
  }

  Status readOnLead(const PartitionOptions& options) {
    Result<InputRead> read = readWholeInput(input_, options);
    if (!read) return read.status();
    split_.read = std::move(*read);
    return {};
  }

  // The nodes too big for memory split by streamed passes over the work files, each level's
  // nodes shared out among the ranks: every rank ends with the list of the nodes left.
  Status splitTogether() {
    reportActivity("splitting its share of the partition's large nodes");
    const PartitionOptions options = pointPartitionOptions(options_, plan_, frame_, work_);
    const LevelShare share{clusterRank(), clusterSize(), agreeAcrossRanks, gatherAcrossRanks,
                           [](std::uint64_t done) { reportProgress("split", done); }};
    Partition mine;  // rank 0's is the job's
    Result<std::vector<PartitionNode>> nodes = [&] {
      // Counted by level: about one pass over every point a level.
      const JobProgress progress(fmt::format("points: streamed splits, {} ranks", clusterSize()),
                                 "split", streamedPoints(options));
      tbb::task_arena arena(plan_.threads);
      return arena.execute([&] { return splitLargeNodes(split_.read, options, mine, share); });
    }();
    if (!nodes) return nodes.status();
    split_.nodes = std::move(*nodes);
    if (lead_) split_.partition = std::move(mine);
    return {};
  }

  // Every rank splits its share of the nodes to rank in memory and ranks each block as it comes
  // out (as one process does); each node's summary says it is done.
  Status rankTogether(std::span<const PartitionNode> all) {
    const std::vector<PartitionNode> mine = nodeShare(all, clusterRank(), clusterSize());
    std::uint64_t total = 0, share = 0;
    for (const PartitionNode& n : all) total += n.count;
    for (const PartitionNode& n : mine) share += n.count;
    reportActivity(fmt::format("splitting and ranking {} of the partition's {} nodes ({} points)",
                               mine.size(), all.size(), share));
    {
      // Shown until every rank is done, so that the bar ends at the job's total.
      const JobProgress progress(fmt::format("points: partition, {} ranks", clusterSize()),
                                 "points", total);
      LODFORGE_TRY(agreeAcrossRanks(splitMine(mine)));
    }
    Result<std::vector<std::uint64_t>> points = gatherAcrossRanks(std::span(&share, 1));
    if (!points) return points.status();
    stats_.rankPoints = std::move(*points);
    return {};
  }

  Status splitMine(std::span<const PartitionNode> mine) {
    PartitionOptions options = pointPartitionOptions(options_, plan_, frame_, work_);
    NodeRanking ranking(work_, hasNormals_, options_);
    ranking.attach(options);
    const NodeStaging staging = ranking.staging(clusterRank());
    const InputRead& read = split_.read;
    tbb::task_arena arena(plan_.threads);
    return arena
        .execute([&] {
          return splitNodesInMemory(
              read, mine, options, [](std::uint64_t done) { reportProgress("points", done); },
              &staging);
        })
        .status();
  }

  // Rank 0: every node's blocks in name order, the tolerances, each block's points per depth;
  // written for the other ranks.
  Status planOnLead() {
    reportActivity("choosing the tolerances");
    Result<PointPlan> plan = planContents(work_, split_.read, split_.nodes, options_,
                                          split_.partition, stats_, release_);
    if (!plan) return plan.status();
    contents_ = std::move(*plan);
    return {};
  }

  // The other ranks: rank 0's plan.
  Status readPlan() {
    Result<std::optional<PointPlan>> plan = resumedPlan(work_, split_.read);
    if (!plan) return plan.status();
    if (!*plan) return ioError(work_ + "/plan.json", "is missing");
    contents_ = std::move(**plan);
    return {};
  }

  // Every rank writes its share of the tiles into the staging folder.
  Status writeShare() {
    nodes_ = tileTree(contents_.blocks);
    std::uint64_t withContent = 0;
    for (const auto& [name, node] : nodes_) withContent += node.uri.empty() ? 0u : 1u;
    reportActivity("writing its share of the tiles");
    ContentsWritten mine;
    {
      const JobProgress progress(fmt::format("tiles: contents, {} ranks", clusterSize()), "tiles",
                                 withContent);
      Result<ContentsWritten> written = writeContents(
          nodes_, contents_.blocks, options_,
          {info_.hasColors, info_.attributes & options_.attributes, &info_.extras}, stagingPath(),
          {.rank = clusterRank(), .ranks = clusterSize(), .resumed = stats_.resumed});
      LODFORGE_TRY(agreeAcrossRanks(written.status()));
      mine = *written;
    }
    Result<std::vector<std::uint64_t>> tiles = gatherAcrossRanks(std::span(&mine.tiles, 1));
    if (!tiles) return tiles.status();
    stats_.rankTiles = std::move(*tiles);
    stats_.tiles = withContent;
    Result<std::uint64_t> kept = sumAcrossRanks(mine.kept);
    if (!kept) return kept.status();
    stats_.tilesResumed = *kept;
    return {};
  }

  Status finishOnLead() {
    reportActivity("writing the tileset");
    LODFORGE_TRY(writePointTilesetJson(nodes_, contents_.blocks, contents_.taus,
                                       rootTransformOf(frame_, options_), options_.quantize,
                                       stagingPath() + "/tileset.json"));
    stats_.outputBytes = directoryBytes(stagingPath());
    ScopedDirectory staging(stagingPath());
    LODFORGE_TRY(replaceDirectory(staging, output_));
    scope_.finished = true;  // scope_ removes the rest when the job ends
    return {};
  }

  std::string input_, output_;
  const PointTilesOptions& options_;
  bool lead_;
  std::string work_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  PointMemoryPlan plan_;
  WorkLock lock_;
  PointWorkScope scope_;             // rank 0's: what it removes at the end
  SpaceRelease release_;             // the keys and scratch files, once planned (before scope_)
  std::optional<SplitState> state_;  // an interrupted job's, when resuming
  std::optional<CrsToLocal> frame_;
  bool hasNormals_ = false;
  PointCloudInfo info_;
  PointRecordLayout layout_;
  // The input read and split: its nodes to split in memory the same on every rank, the
  // partition (all but the blocks, then with them) rank 0's.
  PointSplit split_;
  PointPlan contents_;  // every rank's
  std::map<std::string, TileNode> nodes_;
  PointTilesStats stats_;
};

}  // namespace

Result<PointTilesStats> writePointTilesAcrossRanks(const std::string& input,
                                                   const std::string& outputDirectory,
                                                   const PointTilesOptions& options) {
  RankedPoints job(input, outputDirectory, options);
  return job.run();
}

}  // namespace lodforge
