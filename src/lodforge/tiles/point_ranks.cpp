#include "lodforge/tiles/point_ranks.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <filesystem>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <type_traits>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/checksum.h"
#include "lodforge/core/cluster.h"
#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/file_queue.h"
#include "lodforge/core/output_claim.h"
#include "lodforge/core/progress.h"
#include "lodforge/tiles/point_steps.h"
#include "lodforge/tiles/tileset.h"
#include "lodforge/tiles/tileset_output.h"

namespace lodforge {

namespace fs = std::filesystem;

namespace {

// A block's positions and extra bytes as rank 0 wrote them: the rank that ranks it checks what
// it reads against this, so a shared file system that shows another host stale pages is an
// error, never a different tileset.
std::uint64_t recordsChecksum(std::span<const CloudPoint> points,
                              std::span<const std::byte> extras) {
  std::vector<Vec3d> positions(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) positions[i] = points[i].position;
  Checksum64 sum;
  sum.update(positions.data(), positions.size() * sizeof(Vec3d));
  sum.update(extras);
  return sum.digest();
}

nlohmann::json boxJson(const Aabbd& box) {
  return {box.min.x, box.min.y, box.min.z, box.max.x, box.max.y, box.max.z};
}

Aabbd boxOf(const nlohmann::json& j) {
  Aabbd box;
  box.add(Vec3d{j[0].get<double>(), j[1].get<double>(), j[2].get<double>()});
  box.add(Vec3d{j[3].get<double>(), j[4].get<double>(), j[5].get<double>()});
  return box;
}

// A queued block: where its records are in the partition's files, and their checksum.
std::string queueItem(std::uint64_t number, const PointBlock& block, std::uint64_t checksum) {
  return nlohmann::json{{"number", number},
                        {"name", block.name},
                        {"first", block.first},
                        {"count", block.count},
                        {"bounds", boxJson(block.bounds)},
                        {"centroid", {block.centroid.x, block.centroid.y, block.centroid.z}},
                        {"checksum", checksum}}
      .dump();
}

struct Queued {
  std::uint64_t number = 0;  // in the queue
  PointBlock block;
  std::uint64_t checksum = 0;
};

Result<Queued> parseQueueItem(const std::string& item, const std::string& queue) {
  const nlohmann::json j = nlohmann::json::parse(item, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return ioError(queue, "a queued block is not JSON");
  Queued q;
  q.number = j.at("number").get<std::uint64_t>();
  q.block.name = j.at("name").get<std::string>();
  q.block.first = j.at("first").get<std::uint64_t>();
  q.block.count = j.at("count").get<std::uint64_t>();
  q.block.bounds = boxOf(j.at("bounds"));
  const nlohmann::json& c = j.at("centroid");
  q.block.centroid = Vec3d{c[0].get<double>(), c[1].get<double>(), c[2].get<double>()};
  q.checksum = j.at("checksum").get<std::uint64_t>();
  return q;
}

class RankedPoints {
 public:
  RankedPoints(const std::string& input, const std::string& output,
               const PointTilesOptions& options)
      : input_(input),
        output_(output),
        options_(options),
        lead_(clusterRank() == 0),
        work_(pointWorkDirectory(output)),
        queue_(work_ + "/queue") {}

  Result<PointTilesStats> run() {
    Result<PointMemoryPlan> plan = planPointMemory(options_.memoryLimit, options_.blockSize);
    LODFORGE_TRY(agreeAcrossRanks(plan.status()));
    plan_ = *plan;
    LODFORGE_TRY(agreeAcrossRanks(lead_ ? claimOnLead() : Status{}));
    setActivityDirectory(work_ + "/ranks");
    LODFORGE_TRY(agreeAcrossRanks(readHeader()));
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

  // Rank 0 claims the output and the work place, and makes the queue.
  Status claimOnLead() {
    LODFORGE_TRY(claimPointWorkPlace(input_, output_, lock_, scope_));
    return queue_.create();
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

  // Rank 0 partitions, queueing every block as it is written, then joins the others in ranking
  // from the queue; the others rank from the start.
  Status rankTogether() {
    Status partitioned;
    if (lead_) {
      reportActivity("reading and partitioning the input");
      partitioned = partitionOnLead();
      // Closed whatever happened, so that no rank waits for blocks that will not come.
      const Status closed = queue_.close(published_, !partitioned.ok());
      if (partitioned.ok()) partitioned = closed;
    }
    const std::optional<JobProgress> progress =
        lead_ && partitioned.ok()
            ? std::optional<JobProgress>(std::in_place,
                                         fmt::format("points: ranking, {} ranks", clusterSize()),
                                         "points", partition_.pointCount)
            : std::nullopt;
    reportActivity("ranking blocks from the queue");
    const Status ranked = partitioned.ok() ? drainQueue() : Status{};
    LODFORGE_TRY(agreeAcrossRanks(partitioned.ok() ? ranked : partitioned));
    const std::uint64_t mine = rankedPoints_;
    Result<std::vector<std::uint64_t>> points = gatherAcrossRanks(std::span(&mine, 1));
    if (!points) return points.status();
    stats_.rankPoints = std::move(*points);
    // Each ranked block's errors to every rank: (queue number, root error, least error).
    Result<std::vector<std::uint64_t>> errors = gatherAcrossRanks(rankedErrors_);
    if (!errors) return errors.status();
    rankedErrors_ = std::move(*errors);
    return {};
  }

  Status partitionOnLead() {
    PartitionOptions options = pointPartitionOptions(options_, plan_, frame_, work_);
    options.blockWritten = [this](const PointBlock& block, std::span<const CloudPoint> points,
                                  std::span<const std::byte> extras) {
      const std::uint64_t number = published_++;
      {
        const std::lock_guard lock(queuedMutex_);
        queuedNames_.resize(std::max<std::size_t>(queuedNames_.size(), number + 1));
        queuedNames_[number] = block.name;
      }
      return queue_.publish(number, queueItem(number, block, recordsChecksum(points, extras)));
    };
    tbb::task_arena arena(plan_.threads);
    Result<Partition> partition = arena.execute([&] { return partitionPoints(input_, options); });
    if (!partition) return partition.status();
    partition_ = std::move(*partition);
    stats_.partitionSeconds = secondsSince(start_);
    return {};
  }

  // This rank's threads claim blocks until the queue is empty and closed.
  Status drainQueue() {
    std::vector<Status> outcomes(static_cast<std::size_t>(plan_.threads));
    tbb::task_arena arena(plan_.threads);
    arena.execute([&] {
      tbb::parallel_for(0, plan_.threads, [&](int worker) {
        std::uint64_t cursor = 0;
        for (;;) {
          Result<std::optional<std::string>> item = queue_.claim(cursor);
          if (!item || !*item) {
            outcomes[static_cast<std::size_t>(worker)] = item.status();
            return;
          }
          const Status ranked = rankQueued(**item);
          if (!ranked.ok()) {
            outcomes[static_cast<std::size_t>(worker)] = ranked;
            return;
          }
        }
      });
    });
    for (const Status& outcome : outcomes) LODFORGE_TRY(outcome);
    return {};
  }

  // One queued block: read from the partition's files, checked, ranked, written to files of
  // its own with its errors beside.
  Status rankQueued(const std::string& item) {
    Result<Queued> queued = parseQueueItem(item, queue_.directory());
    if (!queued) return queued.status();
    PointBlock& block = queued->block;
    block.path = pointsPath();
    block.layout = layout_;
    Result<std::vector<CloudPoint>> points =
        readPointRecords(block.path, layout_, block.first, block.count);
    if (!points) return points.status();
    const std::size_t stride = info_.extras.stride;
    std::vector<std::byte> extras;
    if (stride != 0) {
      Result<std::vector<std::byte>> read = readExtraRecords(
          extrasPath(), static_cast<std::uint32_t>(stride), block.first, block.count);
      if (!read) return read.status();
      extras = std::move(*read);
    }
    if (recordsChecksum(*points, extras) != queued->checksum)
      return ioError(block.path,
                     fmt::format("block {} (records {} to {}) reads differently from what rank 0 "
                                 "wrote: the work directory must be on a file system every rank "
                                 "sees alike (docs/distributed.md)",
                                 block.name, block.first, block.first + block.count));
    std::vector<std::uint32_t> ids(stride == 0 ? 0 : points->size());
    std::iota(ids.begin(), ids.end(), 0u);
    BlockTiles tiles;
    LODFORGE_TRY(rankBlock(*points, ids, block, hasNormals_, options_, work_, tiles));
    LODFORGE_TRY(writeBack(block, *points, ids, extras));
    {
      const std::lock_guard lock(queuedMutex_);
      rankedErrors_.insert(rankedErrors_.end(),
                           {queued->number, std::bit_cast<std::uint32_t>(tiles.rootError),
                            std::bit_cast<std::uint32_t>(tiles.leastError)});
    }
    const std::uint64_t done = rankedPoints_.fetch_add(block.count) + block.count;
    reportProgress("points", done);
    checkpointReached("block");
    return {};
  }

  // The ranked block in place in the partition's files, as one process would leave it (pages
  // the kernel already has: new files cost it more).
  Status writeBack(const PointBlock& block, std::span<const CloudPoint> points,
                   std::span<const std::uint32_t> ids, std::span<const std::byte> extras) {
    Result<WorkFile> file = WorkFile::open(pointsPath());
    if (!file) return file.status();
    std::vector<std::byte> records(points.size() * layout_.bytes());
    LODFORGE_TRY(layout_.encode(points, records.data()));
    LODFORGE_TRY(file->writeAt(block.first * layout_.bytes(), records.data(), records.size()));
    if (extras.empty()) return {};
    const std::size_t stride = info_.extras.stride;
    std::vector<std::byte> gathered(extras.size());
    for (std::size_t i = 0; i < ids.size(); ++i)
      std::copy_n(extras.data() + std::size_t{ids[i]} * stride, stride,
                  gathered.data() + i * stride);
    Result<WorkFile> extrasFile = WorkFile::open(extrasPath());
    if (!extrasFile) return extrasFile.status();
    return extrasFile->writeAt(block.first * stride, gathered.data(), gathered.size());
  }

  // Rank 0: every block's ranked files and errors, the tolerances, each block's points per
  // depth; written for the other ranks.
  Status planContents() {
    reportActivity("choosing the tolerances");
    std::map<std::string, std::array<float, 2>> errors;  // root, least
    for (std::size_t i = 0; i + 2 < rankedErrors_.size(); i += 3)
      errors[queuedNames_.at(rankedErrors_[i])] = {
          std::bit_cast<float>(static_cast<std::uint32_t>(rankedErrors_[i + 1])),
          std::bit_cast<float>(static_cast<std::uint32_t>(rankedErrors_[i + 2]))};
    for (const PointBlock& block : partition_.blocks) {
      BlockTiles tiles = blockTiles(block.name, block.bounds);
      tiles.first = block.first;
      const auto found = errors.find(block.name);
      if (found == errors.end())
        return Error{ErrorKind::kInternal, fmt::format("block {} was not ranked", block.name)};
      tiles.rootError = found->second[0];
      tiles.leastError = found->second[1];
      blocks_.push_back(std::move(tiles));
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
    Result<std::uint64_t> written = [&]() -> Result<std::uint64_t> {
      const JobProgress progress(fmt::format("tiles: contents, {} ranks", clusterSize()), "tiles",
                                 withContent);
      return writeContents(nodes_, blocks_, options_,
                           {info_.hasColors, info_.attributes & options_.attributes, &info_.extras},
                           stagingPath(), {.rank = clusterRank(), .ranks = clusterSize()});
    }();
    LODFORGE_TRY(agreeAcrossRanks(written.status()));
    Result<std::vector<std::uint64_t>> tiles = gatherAcrossRanks(std::span(&*written, 1));
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
  FileQueue queue_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  PointMemoryPlan plan_;
  WorkLock lock_;
  ScopedDirectory scope_;  // rank 0's: what it removes at the end
  std::optional<CrsToLocal> frame_;
  bool hasNormals_ = false;
  PointCloudInfo info_;
  PointRecordLayout layout_;
  Partition partition_;  // rank 0's
  std::atomic<std::uint64_t> published_{0};
  std::atomic<std::uint64_t> rankedPoints_{0};
  std::mutex queuedMutex_;
  std::vector<std::string> queuedNames_;     // rank 0's: each queue number's block
  std::vector<std::uint64_t> rankedErrors_;  // (number, root error bits, least error bits)
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
