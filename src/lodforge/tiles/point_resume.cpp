#include "lodforge/tiles/point_resume.h"

#include <cassert>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/tiling/resume.h"

namespace lodforge {

namespace fs = std::filesystem;

namespace {

std::string statePath(const std::string& workDirectory) {
  return workDirectory + "/state.json";
}

std::string planPath(const std::string& workDirectory) {
  return workDirectory + "/plan.json";
}

std::string nodePath(const std::string& workDirectory, const std::string& nodeName) {
  return workDirectory + "/nodes/" + nodeName + ".json";
}

std::string stagedPath(const std::string& workDirectory, const std::string& nodeName) {
  return workDirectory + "/nodes/" + nodeName + ".staged.json";
}

nlohmann::json vecToJson(const Vec3d& v) {
  return {v.x, v.y, v.z};
}

Vec3d vecFromJson(const nlohmann::json& j) {
  return Vec3d{j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

// A file of JSON, or nothing when it is missing or not JSON.
std::optional<nlohmann::json> readJson(const std::string& path) {
  Result<std::string> text = readFileToString(path, std::uint64_t{1} << 34);
  if (!text) return std::nullopt;
  nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  if (j.is_discarded()) return std::nullopt;
  return j;
}

// The split's work files' sizes (0: missing), as a state records them.
nlohmann::json workFileSizes(const std::string& workDirectory) {
  const auto bytes = [&](const char* name) {
    const Result<std::uint64_t> size = fileSize(workDirectory + "/" + name);
    return size ? *size : 0;
  };
  return {bytes("b.points"), bytes("b.extras")};
}

}  // namespace

nlohmann::json pointRunIdentity(const std::string& input, const PointTilesOptions& options) {
  std::error_code error;
  const Result<std::uint64_t> bytes = fileSize(input);
  const ClusterOptions& cluster = options.cluster;
  return {
      {"workFormat", 2},  // 2: one keys file for every block
      {"input", fs::absolute(input, error).string()},
      {"bytes", bytes ? *bytes : 0},
      {"modified", modifiedTicks(input)},
      {"blockSize", options.blockSize},
      {"tilePoints", options.tilePoints},
      {"cluster", {cluster.alpha1, cluster.alpha2, cluster.neighbours, cluster.colors}},
      {"memoryLimit", options.memoryLimit},
      {"crs", options.crs},
      {"origin", options.origin ? nlohmann::json{options.origin->longitude,
                                                 options.origin->latitude, options.origin->height}
                                : nlohmann::json()},
      {"quantize", options.quantize},
      {"meshopt", options.meshoptCompression},
      {"salvage", options.salvageTruncated},
      {"attributes", options.attributes}};
}

Status saveSplitState(const std::string& workDirectory, const nlohmann::json& identity,
                      const SplitState& state) {
  nlohmann::json nodes = nlohmann::json::array();
  for (const PartitionNode& n : state.nodes)
    nodes.push_back({{"name", n.name},
                     {"first", n.first},
                     {"count", n.count},
                     {"bounds", boundsToJson(n.bounds)},
                     {"sum", vecToJson(n.sum)}});
  const nlohmann::json j = {
      {"identity", identity},
      {"workFiles", workFileSizes(workDirectory)},
      {"count", state.count},
      {"bounds", boundsToJson(state.bounds)},
      {"sum", vecToJson(state.sum)},
      {"truncation", state.truncation ? nlohmann::json(*state.truncation) : nlohmann::json()},
      {"nodes", nodes}};
  return OutputFile::writeWhole(statePath(workDirectory),
                                j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

std::optional<SplitState> loadSplitState(const std::string& workDirectory,
                                         const nlohmann::json& identity) {
  const std::optional<nlohmann::json> j = readJson(statePath(workDirectory));
  if (!j) return std::nullopt;
  try {
    if (j->at("identity") != identity) return std::nullopt;  // other input or options
    // Work files not as the state left them (cut short, removed): start over, not go on.
    if (j->at("workFiles") != workFileSizes(workDirectory)) return std::nullopt;
    SplitState state;
    state.count = j->at("count").get<std::uint64_t>();
    state.bounds = boundsFromJson(j->at("bounds"));
    state.sum = vecFromJson(j->at("sum"));
    if (!j->at("truncation").is_null()) state.truncation = j->at("truncation").get<std::string>();
    for (const nlohmann::json& n : j->at("nodes"))
      state.nodes.push_back({n.at("name").get<std::string>(), n.at("first").get<std::uint64_t>(),
                             n.at("count").get<std::uint64_t>(), boundsFromJson(n.at("bounds")),
                             vecFromJson(n.at("sum"))});
    return state;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;  // damaged: split again
  }
}

bool pointWorkKept(const std::string& workDirectory) {
  std::error_code ignored;
  return fs::exists(statePath(workDirectory), ignored);
}

Status writeRankedNode(const std::string& workDirectory, const std::string& nodeName,
                       const std::string& scratchStem, std::span<const RankedBlock> blocks) {
  nlohmann::json list = nlohmann::json::array();
  for (const RankedBlock& r : blocks)
    list.push_back({{"name", r.block.name},
                    {"first", r.block.first},
                    {"count", r.block.count},
                    {"bounds", boundsToJson(r.block.bounds)},
                    {"centroid", vecToJson(r.block.centroid)},
                    {"rootError", r.rootError},
                    {"leastError", r.leastError}});
  const nlohmann::json out = {{"scratch", scratchStem}, {"blocks", list}};
  return OutputFile::writeWhole(stagedPath(workDirectory, nodeName), out.dump());
}

Status markNodeDone(const std::string& workDirectory, const std::string& nodeName) {
  std::error_code error;
  fs::rename(stagedPath(workDirectory, nodeName), nodePath(workDirectory, nodeName), error);
  if (error) return ioError(nodePath(workDirectory, nodeName), error.message());
  return {};
}

std::vector<bool> rankedNodesDone(const std::string& workDirectory,
                                  std::span<const PartitionNode> nodes) {
  std::vector<bool> done;
  std::error_code ignored;
  for (const PartitionNode& n : nodes)
    done.push_back(fs::exists(nodePath(workDirectory, n.name), ignored));
  return done;
}

Result<std::vector<RankedBlock>> readRankedNodes(const std::string& workDirectory,
                                                 std::span<const PartitionNode> nodes,
                                                 const std::string& path,
                                                 const PointRecordLayout& layout) {
  std::vector<RankedBlock> out;
  for (const PartitionNode& node : nodes) {
    const std::string file = nodePath(workDirectory, node.name);
    const std::optional<nlohmann::json> j = readJson(file);
    if (!j) return ioError(file, "is missing or not JSON: run without --resume to start over");
    try {
      for (const nlohmann::json& b : j->at("blocks")) {
        RankedBlock& r = out.emplace_back();
        r.block.name = b.at("name").get<std::string>();
        r.block.path = path;
        r.block.layout = layout;
        r.block.first = b.at("first").get<std::uint64_t>();
        r.block.count = b.at("count").get<std::uint64_t>();
        r.block.bounds = boundsFromJson(b.at("bounds"));
        r.block.centroid = vecFromJson(b.at("centroid"));
        r.rootError = b.at("rootError").get<float>();
        r.leastError = b.at("leastError").get<float>();
      }
    } catch (const nlohmann::json::exception& e) {
      return ioError(file,
                     fmt::format("is damaged ({}): run without --resume to start over", e.what()));
    }
  }
  // Nodes are in name order and a node's blocks all start with its name.
  return out;
}

Status writePointPlan(const std::string& workDirectory, std::span<const float> taus,
                      std::span<const BlockTiles> blocks, std::span<const PointBlock> partition) {
  assert(blocks.size() == partition.size());
  nlohmann::json plan = {{"taus", taus}, {"blocks", nlohmann::json::array()}};
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const BlockTiles& b = blocks[i];
    plan["blocks"].push_back({{"name", b.name},
                              {"count", partition[i].count},
                              {"first", b.first},
                              {"bounds", boundsToJson(b.bounds)},
                              {"counts", b.counts},
                              {"rootError", b.rootError}});
  }
  return OutputFile::writeWhole(planPath(workDirectory), plan.dump());
}

Result<std::optional<PointPlan>> readPointPlan(const std::string& workDirectory) {
  const std::string path = planPath(workDirectory);
  std::error_code ignored;
  if (!fs::exists(path, ignored)) return std::optional<PointPlan>();
  const std::optional<nlohmann::json> j = readJson(path);
  if (!j) return ioError(path, "is not JSON: run without --resume to start over");
  try {
    PointPlan plan;
    plan.taus = j->at("taus").get<std::vector<float>>();
    for (const nlohmann::json& b : j->at("blocks")) {
      BlockTiles& tiles = plan.blocks.emplace_back();
      tiles.name = b.at("name").get<std::string>();
      tiles.first = b.at("first").get<std::uint64_t>();
      tiles.bounds = boundsFromJson(b.at("bounds"));
      tiles.counts = b.at("counts").get<std::vector<std::uint64_t>>();
      tiles.rootError = b.at("rootError").get<float>();
      PointBlock& block = plan.partition.emplace_back();
      block.name = tiles.name;
      block.count = b.at("count").get<std::uint64_t>();
      block.first = tiles.first;
      block.bounds = tiles.bounds;
    }
    return std::optional<PointPlan>(std::move(plan));
  } catch (const nlohmann::json::exception& e) {
    return ioError(path,
                   fmt::format("is damaged ({}): run without --resume to start over", e.what()));
  }
}

SplitState splitStateOf(const PointSplit& split) {
  return {split.read.count, split.read.bounds, split.read.sum, split.read.truncation, split.nodes};
}

Result<PointSplit> resumedSplit(const SplitState& state, const std::string& input,
                                const PartitionOptions& options) {
  // The header as the first pass read it: the records' layout and the extra fields follow.
  Result<PointReader> reader =
      PointReader::open(input, {.batchPoints = 1,
                                .salvageTruncated = options.salvageTruncated,
                                .readExtras = options.carryExtras});
  if (!reader) return reader.status();
  PointSplit split;
  InputRead& read = split.read;
  read.input = input;
  read.info = reader->info();
  read.layout =
      PointRecordLayout::of(read.info, static_cast<bool>(options.transform), options.normals);
  read.count = state.count;
  read.bounds = state.bounds;
  read.sum = state.sum;
  read.truncation = state.truncation;
  Partition& partition = split.partition;
  partition.info = read.info;
  partition.truncation = read.truncation;
  partition.pointCount = read.count;
  partition.bounds = read.bounds;
  if (read.info.extras.stride != 0) partition.extrasPath = options.workDirectory + "/b.extras";
  split.nodes = state.nodes;
  return split;
}

void NodeRanking::attach(PartitionOptions& partition) {
  partition.blockSink = [this](std::span<CloudPoint> points, std::span<std::uint32_t> ids,
                               PointBlock& block) {
    BlockTiles tiles;
    LODFORGE_TRY(rankBlock(points, ids, block, hasNormals_, options_, work_, tiles));
    checkpointReached("pointblock");
    const std::lock_guard lock(mutex_);
    errors_[block.name] = {tiles.rootError, tiles.leastError};
    return Status{};
  };
}

NodeStaging NodeRanking::staging(int rank) {
  NodeStaging staging;
  staging.scratchStem = fmt::format("scratch-{}", rank);
  staging.staged = [this, stem = staging.scratchStem](const PartitionNode& node,
                                                      std::span<const PointBlock> blocks) {
    std::vector<RankedBlock> ranked;
    {
      const std::lock_guard lock(mutex_);
      for (const PointBlock& b : blocks) {
        const auto errors = errors_.find(b.name);
        if (errors == errors_.end())
          return Status{
              Error{ErrorKind::kInternal, fmt::format("block {} was not ranked", b.name)}};
        ranked.push_back({b, errors->second[0], errors->second[1]});
      }
    }
    LODFORGE_TRY(writeRankedNode(work_, node.name, stem, ranked));
    checkpointReached("pointstaged");
    return Status{};
  };
  staging.placed = [this](const PartitionNode& node) {
    LODFORGE_TRY(markNodeDone(work_, node.name));
    checkpointReached("pointnode");
    return Status{};
  };
  return staging;
}

Result<std::uint64_t> placeStagedNodes(const std::string& workDirectory,
                                       std::span<const PartitionNode> nodes, const InputRead& read,
                                       const PartitionOptions& options) {
  std::uint64_t placed = 0;
  std::error_code ignored;
  for (const PartitionNode& node : nodes) {
    const std::string staged = stagedPath(workDirectory, node.name);
    if (fs::exists(nodePath(workDirectory, node.name), ignored) || !fs::exists(staged, ignored))
      continue;
    const std::optional<nlohmann::json> j = readJson(staged);
    if (!j || !j->contains("scratch") || !j->at("scratch").is_string())
      return ioError(staged, "is damaged: run without --resume to start over");
    LODFORGE_TRY(placeScratchNode(read, options, j->at("scratch").get<std::string>(), node));
    LODFORGE_TRY(markNodeDone(workDirectory, node.name));
    ++placed;
  }
  return placed;
}

std::vector<PartitionNode> nodesToRank(const std::string& workDirectory,
                                       std::span<const PartitionNode> nodes) {
  const std::vector<bool> done = rankedNodesDone(workDirectory, nodes);
  std::vector<PartitionNode> out;
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (!done[i]) out.push_back(nodes[i]);
  return out;
}

BlockTiles rankedBlockTiles(const std::string& workDirectory, const std::string& name,
                            const PointRecordLayout& layout, bool extras) {
  BlockTiles tiles;
  tiles.name = name;
  tiles.path = workDirectory + "/b.points";
  tiles.keysPath = pointKeysPath(workDirectory);
  if (extras) tiles.extrasPath = workDirectory + "/b.extras";
  tiles.layout = layout;
  return tiles;
}

namespace {

// The scratch files of every process: once the plan is written no node is staged again.
void removeScratchFiles(const std::string& workDirectory, SpaceRelease& release) {
  std::error_code error;
  std::vector<fs::path> scratch;
  for (fs::directory_iterator entry(workDirectory, error), end; !error && entry != end;
       entry.increment(error))
    if (entry->path().filename().string().starts_with("scratch-")) scratch.push_back(*entry);
  for (const fs::path& path : scratch) release.remove(path.string());
}

}  // namespace

Result<PointPlan> planContents(const std::string& workDirectory, const InputRead& read,
                               std::span<const PartitionNode> nodes,
                               const PointTilesOptions& options, Partition& partition,
                               PointTilesStats& stats, SpaceRelease& release) {
  const bool extras = read.info.extras.stride != 0;
  Result<std::vector<RankedBlock>> ranked =
      readRankedNodes(workDirectory, nodes, workDirectory + "/b.points", read.layout);
  if (!ranked) return ranked.status();
  PointPlan plan;
  for (RankedBlock& r : *ranked) {
    BlockTiles tiles = rankedBlockTiles(workDirectory, r.block.name, read.layout, extras);
    tiles.first = r.block.first;
    tiles.bounds = r.block.bounds;
    tiles.rootError = r.rootError;
    tiles.leastError = r.leastError;
    plan.blocks.push_back(std::move(tiles));
    partition.blocks.push_back(std::move(r.block));
  }
  noteStats(partition, options, stats);
  Result<std::vector<float>> taus = toleranceSchedule(partition, plan.blocks, options, stats.depth);
  if (!taus) return taus.status();
  plan.taus = std::move(*taus);
  LODFORGE_TRY(countLevels(partition, plan.taus, plan.blocks));
  LODFORGE_TRY(writePointPlan(workDirectory, plan.taus, plan.blocks, partition.blocks));
  release.remove(pointKeysPath(workDirectory));
  removeScratchFiles(workDirectory, release);
  plan.partition = partition.blocks;
  return plan;
}

Result<std::optional<PointPlan>> resumedPlan(const std::string& workDirectory,
                                             const InputRead& read) {
  Result<std::optional<PointPlan>> plan = readPointPlan(workDirectory);
  if (!plan || !*plan) return plan;
  const bool extras = read.info.extras.stride != 0;
  for (std::size_t i = 0; i < (*plan)->blocks.size(); ++i) {
    BlockTiles& b = (*plan)->blocks[i];
    BlockTiles tiles = rankedBlockTiles(workDirectory, b.name, read.layout, extras);
    tiles.first = b.first;
    tiles.bounds = b.bounds;
    tiles.counts = std::move(b.counts);
    tiles.rootError = b.rootError;
    b = std::move(tiles);
    PointBlock& block = (*plan)->partition[i];
    block.path = b.path;
    block.layout = read.layout;
  }
  return plan;
}

}  // namespace lodforge
