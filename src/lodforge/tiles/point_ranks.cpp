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
#include "lodforge/tiles/point_steps.h"
#include "lodforge/tiles/tileset.h"

namespace lodforge {

namespace {

nlohmann::json boxJson(const Aabbd& box) {
  return {box.min.x, box.min.y, box.min.z, box.max.x, box.max.y, box.max.z};
}

Aabbd boxOf(const nlohmann::json& j) {
  Aabbd box;  // the corners as written (adding them would turn a max of +0 into -0 beside -0)
  box.min = Vec3d{j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
  box.max = Vec3d{j[3].get<double>(), j[4].get<double>(), j[5].get<double>()};
  return box;
}

nlohmann::json vecJson(const Vec3d& v) {
  return {v.x, v.y, v.z};
}

Vec3d vecOf(const nlohmann::json& j) {
  return Vec3d{j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

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

// A rank's ranked blocks for rank 0: where each lies and its errors.
std::string blocksJson(std::span<const PointBlock> blocks,
                       const std::map<std::string, BlockTiles>& tiles) {
  nlohmann::json out = nlohmann::json::array();
  for (const PointBlock& b : blocks) {
    const BlockTiles& t = tiles.at(b.name);
    out.push_back({{"name", b.name},
                   {"first", b.first},
                   {"count", b.count},
                   {"bounds", boxJson(b.bounds)},
                   {"centroid", vecJson(b.centroid)},
                   {"rootError", t.rootError},
                   {"leastError", t.leastError}});
  }
  return out.dump();
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
    setActivityDirectory(work_ + "/ranks");
    LODFORGE_TRY(agreeAcrossRanks(readHeader()));
    Result<bool> sliced = readTogether();
    if (!sliced) return sliced.status();
    stats_.readInSlices = *sliced;
    stats_.readSeconds = secondsSince(start_);
    recordStage("input");
    LODFORGE_TRY(splitTogether());
    stats_.partitionSeconds = secondsSince(start_);
    LODFORGE_TRY(rankTogether());
    stats_.rankingSeconds = secondsSince(start_);
    recordStage("partition and ranking");
    LODFORGE_TRY(agreeAcrossRanks(lead_ ? planContents() : Status{}));
    LODFORGE_TRY(agreeAcrossRanks(lead_ ? Status{} : readPlan()));
    LODFORGE_TRY(writeShare());
    recordStage("contents");
    LODFORGE_TRY(agreeAcrossRanks(lead_ ? finishOnLead() : Status{}));
    stats_.ranks = clusterSize();
    stats_.rankStages = rankStages();
    stats_.seconds = secondsSince(start_);
    return stats_;
  }

 private:
  std::string pointsPath() const { return work_ + "/b.points"; }
  std::string extrasPath() const { return work_ + "/b.extras"; }
  // A block's tiles as ranked in place (its first record and errors still to fill in).
  BlockTiles blockTiles(const std::string& name, const Aabbd& bounds) const {
    BlockTiles tiles;
    tiles.name = name;
    tiles.path = pointsPath();
    tiles.keysPath = work_ + "/" + name + ".keys";
    if (info_.extras.stride != 0) tiles.extrasPath = extrasPath();
    tiles.layout = layout_;
    tiles.bounds = bounds;
    return tiles;
  }
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

  // Rank 0 claims the output and the work place.
  Status claimOnLead() { return claimPointWorkPlace(input_, output_, lock_, scope_); }

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
      Result<std::vector<std::uint64_t>> totals =
          gatherAcrossRanks(lead_ ? encodeSlice(SliceRead{read_.count, read_.bounds, {read_.sum}})
                                  : std::vector<std::uint64_t>{});
      if (!totals) return totals.status();
      LODFORGE_TRY(addSlicesFrom(*totals, 1));
      return false;
    }
    if (lead_) read_ = std::move(*files);
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
    addSlices(*decoded, read_);
    read_.input = input_;
    read_.info = info_;
    read_.layout = layout_;
    return {};
  }

  // The points the streamed levels go over: the input once per level above the allowance.
  std::uint64_t streamedPoints(const PartitionOptions& options) const {
    const std::uint64_t inMemory = inMemoryPoints(options, info_.extras.stride);
    std::uint64_t total = 0;
    for (std::uint64_t n = read_.count; n > inMemory; n = (n + 1) / 2) total += read_.count;
    return total;
  }

  Status readOnLead(const PartitionOptions& options) {
    Result<InputRead> read = readWholeInput(input_, options);
    if (!read) return read.status();
    read_ = std::move(*read);
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
      return arena.execute([&] { return splitLargeNodes(read_, options, mine, share); });
    }();
    if (!nodes) return nodes.status();
    memoryNodes_ = std::move(*nodes);
    if (lead_) partition_ = std::move(mine);
    return {};
  }

  // Every rank splits its share of the nodes in memory and ranks each block as it comes out (as
  // one process does), then lists its blocks for rank 0.
  Status rankTogether() {
    const std::vector<PartitionNode>& all = memoryNodes_;
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
      std::map<std::string, BlockTiles> ranked;
      Result<std::vector<PointBlock>> blocks = splitMine(mine, ranked);
      Status listed = blocks.status();
      if (blocks)
        listed = OutputFile::writeWhole(fmt::format("{}/blocks-{}.json", work_, clusterRank()),
                                        blocksJson(*blocks, ranked));
      LODFORGE_TRY(agreeAcrossRanks(listed));
    }
    Result<std::vector<std::uint64_t>> points = gatherAcrossRanks(std::span(&share, 1));
    if (!points) return points.status();
    stats_.rankPoints = std::move(*points);
    return {};
  }

  Result<std::vector<PointBlock>> splitMine(std::span<const PartitionNode> mine,
                                            std::map<std::string, BlockTiles>& ranked) {
    PartitionOptions options = pointPartitionOptions(options_, plan_, frame_, work_);
    std::mutex mutex;
    options.blockSink = [&](std::span<CloudPoint> points, std::span<std::uint32_t> ids,
                            PointBlock& block) {
      BlockTiles tiles;
      LODFORGE_TRY(rankBlock(points, ids, block, hasNormals_, options_, work_, tiles));
      checkpointReached("block");
      const std::lock_guard lock(mutex);
      ranked[block.name] = std::move(tiles);
      return Status{};
    };
    const InputRead& read = read_;
    tbb::task_arena arena(plan_.threads);
    return arena.execute([&] {
      return splitNodesInMemory(read, mine, options,
                                [](std::uint64_t done) { reportProgress("points", done); });
    });
  }

  // Rank 0: every rank's blocks in name order, the tolerances, each block's points per depth;
  // written for the other ranks.
  Status planContents() {
    reportActivity("choosing the tolerances");
    std::vector<std::pair<PointBlock, std::array<float, 2>>> listed;
    for (int r = 0; r < clusterSize(); ++r) {
      const std::string path = fmt::format("{}/blocks-{}.json", work_, r);
      Result<std::string> text = readFileToString(path, std::uint64_t{1} << 34);
      if (!text) return text.status();
      const nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
      if (j.is_discarded()) return ioError(path, "is not JSON");
      for (const nlohmann::json& b : j) {
        PointBlock block;
        block.name = b.at("name").get<std::string>();
        block.path = pointsPath();
        block.layout = layout_;
        block.first = b.at("first").get<std::uint64_t>();
        block.count = b.at("count").get<std::uint64_t>();
        block.bounds = boxOf(b.at("bounds"));
        block.centroid = vecOf(b.at("centroid"));
        listed.push_back(
            {std::move(block), {b.at("rootError").get<float>(), b.at("leastError").get<float>()}});
      }
    }
    std::sort(listed.begin(), listed.end(),
              [](const auto& a, const auto& b) { return a.first.name < b.first.name; });
    for (auto& [block, errors] : listed) {
      BlockTiles tiles = blockTiles(block.name, block.bounds);
      tiles.first = block.first;
      tiles.rootError = errors[0];
      tiles.leastError = errors[1];
      blocks_.push_back(std::move(tiles));
      partition_.blocks.push_back(std::move(block));
    }
    noteStats(partition_, options_, stats_);
    Result<std::vector<float>> taus =
        toleranceSchedule(partition_, blocks_, options_, stats_.depth);
    if (!taus) return taus.status();
    taus_ = std::move(*taus);
    LODFORGE_TRY(countLevels(partition_, taus_, blocks_));
    nlohmann::json plan = {{"taus", taus_}, {"blocks", nlohmann::json::array()}};
    for (const BlockTiles& b : blocks_)
      plan["blocks"].push_back({{"name", b.name},
                                {"first", b.first},
                                {"bounds", boxJson(b.bounds)},
                                {"counts", b.counts},
                                {"rootError", b.rootError}});
    return OutputFile::writeWhole(work_ + "/plan.json", plan.dump());
  }

  // The other ranks: rank 0's plan.
  Status readPlan() {
    const std::string path = work_ + "/plan.json";
    Result<std::string> text = readFileToString(path, std::uint64_t{1} << 34);
    if (!text) return text.status();
    const nlohmann::json plan = nlohmann::json::parse(*text, nullptr, false);
    if (plan.is_discarded()) return ioError(path, "is not JSON");
    taus_ = plan.at("taus").get<std::vector<float>>();
    for (const nlohmann::json& b : plan.at("blocks")) {
      BlockTiles tiles = blockTiles(b.at("name").get<std::string>(), boxOf(b.at("bounds")));
      tiles.first = b.at("first").get<std::uint64_t>();
      tiles.counts = b.at("counts").get<std::vector<std::uint64_t>>();
      tiles.rootError = b.at("rootError").get<float>();
      blocks_.push_back(std::move(tiles));
    }
    return {};
  }

  // Every rank writes its share of the tiles into the staging folder.
  Status writeShare() {
    nodes_ = tileTree(blocks_);
    std::uint64_t withContent = 0;
    for (const auto& [name, node] : nodes_) withContent += node.uri.empty() ? 0u : 1u;
    reportActivity("writing its share of the tiles");
    std::uint64_t mine = 0;
    {
      const JobProgress progress(fmt::format("tiles: contents, {} ranks", clusterSize()), "tiles",
                                 withContent);
      Result<std::uint64_t> written =
          writeContents(nodes_, blocks_, options_,
                        {info_.hasColors, info_.attributes & options_.attributes, &info_.extras},
                        stagingPath(), {.rank = clusterRank(), .ranks = clusterSize()});
      LODFORGE_TRY(agreeAcrossRanks(written.status()));
      mine = *written;
    }
    Result<std::vector<std::uint64_t>> tiles = gatherAcrossRanks(std::span(&mine, 1));
    if (!tiles) return tiles.status();
    stats_.rankTiles = std::move(*tiles);
    stats_.tiles = withContent;
    return {};
  }

  Status finishOnLead() {
    reportActivity("writing the tileset");
    LODFORGE_TRY(writePointTilesetJson(nodes_, blocks_, taus_, rootTransformOf(frame_, options_),
                                       options_.quantize, stagingPath() + "/tileset.json"));
    stats_.outputBytes = directoryBytes(stagingPath());
    ScopedDirectory staging(stagingPath());
    return replaceDirectory(staging, output_);  // scope_ removes the rest when the job ends
  }

  std::string input_, output_;
  const PointTilesOptions& options_;
  bool lead_;
  std::string work_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  PointMemoryPlan plan_;
  WorkLock lock_;
  ScopedDirectory scope_;  // rank 0's: what it removes at the end
  std::optional<CrsToLocal> frame_;
  bool hasNormals_ = false;
  PointCloudInfo info_;
  PointRecordLayout layout_;
  InputRead read_;       // rank 0's: the input in the work files, when read in slices
  Partition partition_;  // rank 0's
  // The nodes split in memory, the same on every rank.
  std::vector<PartitionNode> memoryNodes_;
  std::vector<BlockTiles> blocks_;
  std::vector<float> taus_;
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
