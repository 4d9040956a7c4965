#include "lodforge/tiles/point_steps.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
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
#include "lodforge/tiles/point_resume.h"
#include "lodforge/tiles/tileset.h"
#include "lodforge/tiles/tileset_output.h"

namespace lodforge {

namespace fs = std::filesystem;

namespace {

// WebGL's usual MAX_VERTEX_ATTRIBS: a primitive with more does not draw.
constexpr std::size_t kViewerVertexAttributes = 16;

// POSITION, NORMAL, COLOR_0 if any, one per lidar field carried and per extra field.
std::size_t vertexAttributeCount(const PointCloudInfo& info, std::uint32_t carried) {
  std::size_t count = 2 + (info.hasColors ? 1 : 0);
  for (const PointAttributeField& field : pointAttributeFields())
    count += (carried & field.bit) != 0 ? 1 : 0;
  if ((carried & kAttrExtras) != 0) count += info.extras.fields.size();
  return count;
}

int depthOf(const PointBlock& block) {
  return static_cast<int>(block.name.size()) - 1;
}

// The clustering tree with each node's error replaced by its tile error (still monotone: the
// error, the radius and the reach are).
std::vector<ClusterNode> tileErrorTree(std::vector<ClusterNode> tree,
                                       std::span<const std::uint32_t> reps,
                                       std::span<const CloudPoint> points) {
  const std::vector<float> reach = representativeReach(tree, reps, points);
  for (std::size_t i = 0; i < tree.size(); ++i) tree[i].error = pointTileError(tree[i], reach[i]);
  return tree;
}

// Each point's normal made what its tile will write, exactly: the GLB writer's bytes for the
// y-up normal, turned back to z-up and over 127, which the work record's bytes keep exactly
// (the clustering is done with the float normals by then).
void keepTileNormals(std::span<CloudPoint> points) {
  for (CloudPoint& p : points) {
    const std::array<std::int8_t, 4> q =
        glbPackNormal(toYUp(normalizeOr(p.normal, Vec3f{0, 0, 1})));
    // toYUp maps (x, y, z) to (x, z, −y); its inverse maps (a, b, c) to (a, −c, b).
    p.normal =
        Vec3f{static_cast<float>(q[0]), static_cast<float>(-q[2]), static_cast<float>(q[1])} /
        127.0f;
  }
}

// The y-up bytes tiles write for normals that keepTileNormals made (127 × each axis is a whole
// number there).
std::vector<std::array<std::int8_t, 4>> tileNormalBytes(std::span<const CloudPoint> points) {
  std::vector<std::array<std::int8_t, 4>> packed(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3f n = points[i].normal * 127.0f;
    const auto byte = [](float v) { return static_cast<std::int8_t>(roundToLong(v)); };
    packed[i] = {byte(n.x), byte(n.z), byte(-n.y), 0};
  }
  return packed;
}

Result<std::vector<float>> readKeys(const BlockTiles& block, std::uint64_t count) {
  Result<WorkFile> in = WorkFile::open(block.keysPath);
  if (!in) return in.status();
  std::vector<float> keys(count);
  LODFORGE_TRY(in->readAt(block.first * sizeof(float), keys.data(), keys.size() * sizeof(float)));
  return keys;
}

// The least τ of the block's tree whose cut holds at most `budget` points: the (budget + 1)-th
// key (toleranceForResident over the tree, from the keys alone).
float toleranceForBudget(std::span<const float> keys, const BlockTiles& block, std::size_t budget) {
  if (budget >= keys.size()) return block.leastError;
  return std::min(keys[budget], block.rootError);
}

Status writeContent(const TileNode& node, std::span<const BlockTiles> blocks,
                    const PointTilesOptions& options, const ContentFields& fields,
                    const std::string& path) {
  const bool colors = fields.colors;
  const bool extras = (fields.attributes & kAttrExtras) != 0 && fields.extras != nullptr;
  std::vector<CloudPoint> points;
  std::vector<std::byte> extraBytes;
  points.reserve(node.points);
  for (std::size_t b : node.blocks) {
    const BlockTiles& block = blocks[b];
    const auto d = static_cast<std::size_t>(node.depth);
    std::uint64_t first = block.first;
    for (std::size_t k = 0; k < d; ++k) first += block.counts[k];
    Result<std::vector<CloudPoint>> section =
        readPointRecords(block.path, block.layout, first, block.counts[d]);
    if (!section) return section.status();
    points.insert(points.end(), section->begin(), section->end());
    if (!extras) continue;
    Result<std::vector<std::byte>> bytes =
        readExtraRecords(block.extrasPath, fields.extras->stride, first, block.counts[d]);
    if (!bytes) return bytes.status();
    extraBytes.insert(extraBytes.end(), bytes->begin(), bytes->end());
  }
  Aabbd content;
  for (const CloudPoint& p : points) content.add(p.position);
  const Vec3d center = content.center();
  // Normals as bytes already (the work records kept them so) or as floats.
  const bool normalBytes = !node.blocks.empty() && blocks[node.blocks.front()].layout.normalBytes();
  std::vector<Vec3f> positions(points.size()), normals(normalBytes ? 0 : points.size());
  std::vector<Rgba8> rgba(colors ? points.size() : 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    positions[i] = toYUp(toFloat(points[i].position - center));
    if (!normalBytes) normals[i] = toYUp(normalizeOr(points[i].normal, Vec3f{0, 0, 1}));
    if (colors) rgba[i] = points[i].color;
  }
  const std::vector<std::array<std::int8_t, 4>> packedNormals =
      normalBytes ? tileNormalBytes(points) : std::vector<std::array<std::int8_t, 4>>{};
  const PointTileAttributes lidar =
      pointTileAttributes(points, fields.attributes, {fields.extras, extraBytes});
  Result<GlbWriter> writer = GlbWriter::create(
      path,
      {.doubleSided = false, .meshoptCompression = options.meshoptCompression, .flatScene = true});
  if (!writer) return writer.status();
  if (!lidar.metadata.empty()) writer->setStructuralMetadata(lidar.metadata);
  Result<std::uint32_t> mesh = writer->addMesh(
      {.positions = positions,
       .normals = normals,
       .colors = rgba,
       .indices = {},
       .quantized = options.quantize,
       .points = true,
       .extraAttributes = lidar.attributes,
       .propertyAttribute = lidar.metadata.empty() ? std::nullopt : std::optional<std::uint32_t>(0),
       .packedNormals = packedNormals},
      "points");
  if (!mesh) return mesh.status();
  const Mat4d placed = Mat4d::translation(toYUp(center));
  writer->addNode("points", *mesh, &placed);
  return writer->finish();
}

}  // namespace

std::string pointKeysPath(const std::string& workDirectory) {
  return workDirectory + "/b.keys";
}

// Sorts the block's points by key (the partition writes them back in that order) and writes
// the keys at their records' place in the keys file.
Status rankBlock(std::span<CloudPoint> points, std::span<std::uint32_t> ids,
                 const PointBlock& block, bool hasNormals, const PointTilesOptions& options,
                 const std::string& workDirectory, BlockTiles& out) {
  std::vector<std::uint32_t> firstPoint;
  ClusterOptions cluster = options.cluster;
  cluster.colors = false;  // tiles draw the points' own colours
  std::vector<ClusterNode> tree =
      clusterBlock(points, block.centroid, hasNormals, cluster, &firstPoint, ids);
  const std::vector<std::uint32_t> reps =
      clusterRepresentatives(tree, points, firstPoint, block.centroid);
  tree = tileErrorTree(std::move(tree), reps, points);
  std::vector<float> key = pointKeys(tree, reps);
  out.leastError = tree.front().error;
  for (const ClusterNode& node : tree) out.leastError = std::min(out.leastError, node.error);
  if (block.layout.normalBytes()) keepTileNormals(points);
  const std::vector<std::uint32_t> order = descendingKeyOrder(key);
  applyOrder(order, points);
  applyOrder(order, ids);
  applyOrder(order, std::span(key));  // written beside, sorted like the points
  out.name = block.name;
  out.path = block.path;
  out.layout = block.layout;
  out.first = block.first;
  out.keysPath = pointKeysPath(workDirectory);
  out.bounds = block.bounds;
  out.rootError = tree.front().error;
  // One file for every block's keys, each at its records' place: a file per block cost a
  // creation each (1.4 ms apiece on ext4 when a previous run's files were removed minutes before).
  Result<WorkFile> keys = WorkFile::open(out.keysPath, true);
  if (!keys) return keys.status();
  return keys->writeAt(block.first * sizeof(float), key.data(), key.size() * sizeof(float));
}

// τ_d per depth of the partition tree: a tile at depth d should hold about `tilePoints`, so the
// cut at τ_d keeps 2^d · tilePoints of the N points (the median over up to 8 sample blocks),
// and τ never grows with depth.
Result<std::vector<float>> toleranceSchedule(const Partition& partition,
                                             std::span<const BlockTiles> blocks,
                                             const PointTilesOptions& options, int maxDepth) {
  std::vector<float> taus(static_cast<std::size_t>(maxDepth), 0);
  if (maxDepth == 0) return taus;
  const std::size_t samples = std::min<std::size_t>(8, partition.blocks.size());
  std::vector<std::vector<float>> perSample(samples);
  for (std::size_t s = 0; s < samples; ++s) {
    const std::size_t b = s * partition.blocks.size() / samples;
    const std::uint64_t count = partition.blocks[b].count;
    Result<std::vector<float>> keys = readKeys(blocks[b], count);
    if (!keys) return keys.status();
    for (int d = 0; d < maxDepth; ++d) {
      const double share = std::min(1.0, std::ldexp(static_cast<double>(options.tilePoints), d) /
                                             static_cast<double>(partition.pointCount));
      const auto budget =
          static_cast<std::size_t>(std::max(1.0, share * static_cast<double>(count)));
      perSample[s].push_back(toleranceForBudget(*keys, blocks[b], budget));
    }
  }
  for (int d = 0; d < maxDepth; ++d) {
    std::vector<float> values;
    for (const auto& v : perSample) values.push_back(v[static_cast<std::size_t>(d)]);
    std::nth_element(values.begin(),
                     values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
    taus[static_cast<std::size_t>(d)] = values[values.size() / 2];
    if (d > 0)
      taus[static_cast<std::size_t>(d)] =
          std::min(taus[static_cast<std::size_t>(d)], taus[static_cast<std::size_t>(d - 1)]);
  }
  return taus;
}

// Each block's points per depth, now that the τ are known: the shallowest depth whose τ is
// below a point's key holds it, the block's own tile the rest.
Status countLevels(const Partition& partition, std::span<const float> taus,
                   std::span<BlockTiles> blocks) {
  std::vector<Status> failures(blocks.size());
  tbb::parallel_for(std::size_t{0}, blocks.size(), [&](std::size_t b) {
    const int depth = depthOf(partition.blocks[b]);
    Result<std::vector<float>> keys = readKeys(blocks[b], partition.blocks[b].count);
    if (!keys) {
      failures[b] = keys.status();
      return;
    }
    std::vector<std::uint64_t>& counts = blocks[b].counts;
    counts.assign(static_cast<std::size_t>(depth) + 1, 0);
    std::size_t d = 0;
    for (const float key : *keys) {
      while (d < static_cast<std::size_t>(depth) && !(taus[d] < key)) ++d;
      ++counts[d];
    }
  });
  for (const Status& f : failures) LODFORGE_TRY(f);
  return Status{};
}

// Georeferencing: a CRS (given, or the input's) sets up the local east-north-up frame at the
// first point; the partition applies it while the input is read (one thread).
Result<std::optional<CrsToLocal>> localFrame(const std::string& input,
                                             const PointTilesOptions& options,
                                             PointTilesStats& stats, bool& hasNormals) {
  Result<PointReader> probe =
      PointReader::open(input, {.batchPoints = 1, .salvageTruncated = options.salvageTruncated});
  if (!probe) return probe.status();
  hasNormals = probe->info().hasNormals;
  stats.crs = !options.crs.empty() || options.origin ? options.crs : probe->info().crs;
  if (stats.crs.empty()) return std::optional<CrsToLocal>();
  PointBatch first;
  Result<bool> some = probe->next(first);
  if (!some) return some.status();
  if (!*some) return badInput(input, "the file has no points");
  const std::string from =
      options.crs.empty() ? fmt::format("the coordinate system in {}", input) : "--crs";
  Result<CrsToLocal> created = CrsToLocal::create(stats.crs, first.positions.front(), from);
  if (!created) return created.status();
  return std::optional<CrsToLocal>(std::move(*created));
}

// The tile tree: every prefix of a block's name is a tile; those with points get a content URI.
std::map<std::string, TileNode> tileTree(std::span<const BlockTiles> blocks) {
  std::map<std::string, TileNode> nodes;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const std::string& name = blocks[b].name;
    for (std::size_t length = 1; length <= name.size(); ++length) {
      TileNode& node = nodes[name.substr(0, length)];
      node.name = name.substr(0, length);
      node.depth = static_cast<int>(length) - 1;
      node.blocks.push_back(b);
      node.bounds.add(blocks[b].bounds);
      node.points += blocks[b].counts[static_cast<std::size_t>(node.depth)];
      if (length < name.size()) {
        const std::string child = name.substr(0, length + 1);
        if (std::find(node.children.begin(), node.children.end(), child) == node.children.end())
          node.children.push_back(child);
      }
    }
  }
  for (auto& [name, node] : nodes) {
    std::sort(node.children.begin(), node.children.end());
    if (node.points > 0) node.uri = "tiles/" + name + ".glb";
  }
  return nodes;
}

namespace {

// Of the tiles with content (in name order), those of `share.rank`.
std::vector<const TileNode*> contentShare(const std::map<std::string, TileNode>& nodes,
                                          ContentShare share) {
  std::vector<const TileNode*> withContent, mine;
  for (const auto& [name, node] : nodes)
    if (!node.uri.empty()) withContent.push_back(&node);
  if (share.ranks <= 1) return withContent;
  std::vector<std::uint64_t> work;  // + 1: tiles of few points are spread too
  for (const TileNode* node : withContent) work.push_back(node->points + 1);
  const std::vector<int> owner = dealLargestFirst(work, share.ranks);
  for (std::size_t i = 0; i < withContent.size(); ++i)
    if (owner[i] == share.rank) mine.push_back(withContent[i]);
  return mine;
}

// body(i) for i in [0, n), each thread taking the next i: tiles in name order (a parent before
// its children) with blocks' last readers done throughout. (parallel_for's halves left the first
// tiles of the second half, the ancestors of half the blocks, to the end.)
void inNameOrder(std::size_t n, const std::function<void(std::size_t)>& body) {
  std::atomic<std::size_t> next{0};
  tbb::parallel_for(0, tbb::this_task_arena::max_concurrency(), [&](int) {
    for (std::size_t i = next++; i < n; i = next++) body(i);
  });
}

// How many of `tiles` read each block's records.
std::vector<std::atomic<std::uint32_t>> blockReaders(std::span<const TileNode* const> tiles,
                                                     std::size_t blocks) {
  std::vector<std::atomic<std::uint32_t>> readers(blocks);
  for (const TileNode* tile : tiles)
    for (std::size_t b : tile->blocks) readers[b].fetch_add(1, std::memory_order_relaxed);
  return readers;
}

// A block's records (and extra bytes) once the last tile reading them is written.
void releaseBlock(const BlockTiles& block, std::size_t extrasStride, SpaceRelease& release) {
  std::uint64_t count = 0;
  for (std::uint64_t c : block.counts) count += c;
  release.punch(block.path, block.first * block.layout.bytes(), count * block.layout.bytes());
  if (extrasStride != 0 && !block.extrasPath.empty())
    release.punch(block.extrasPath, block.first * extrasStride, count * extrasStride);
}

}  // namespace

Result<ContentsWritten> writeContents(const std::map<std::string, TileNode>& nodes,
                                      std::span<const BlockTiles> blocks,
                                      const PointTilesOptions& options, const ContentFields& fields,
                                      const std::string& tilesetDirectory, ContentShare share,
                                      SpaceRelease* release) {
  const std::vector<const TileNode*> mine = contentShare(nodes, share);
  assert(release == nullptr || share.ranks <= 1);  // a job's ranks share the blocks
  std::vector<std::atomic<std::uint32_t>> readers =
      blockReaders(release ? mine : std::span<const TileNode* const>{}, blocks.size());
  const std::size_t extrasStride = fields.extras ? fields.extras->stride : 0;
  std::vector<Status> written(mine.size());
  std::atomic<std::uint64_t> kept{0};
  // A job's progress is rank 0's JobProgress, from every rank's reports.
  std::optional<Progress> writing;
  if (share.ranks <= 1) writing.emplace("tiles: contents", mine.size());
  std::atomic<std::uint64_t> done{0};
  inNameOrder(mine.size(), [&](std::size_t i) {
    if (cancelRequested()) return;
    const std::string path = tilesetDirectory + "/" + mine[i]->uri;
    std::error_code error;  // (a missing tile is no error)
    const bool there = share.resumed && fs::exists(path, error);
    if (error) {
      // Not rewritten: its blocks may have been given back once it was written.
      written[i] =
          ioError(path, fmt::format("cannot tell whether it is written: {}", error.message()));
    } else if (there) {
      ++kept;
    } else {
      written[i] = writeContent(*mine[i], blocks, options, fields, path);
      checkpointReached("tile");
    }
    if (release && written[i].ok())
      for (std::size_t b : mine[i]->blocks)
        if (readers[b].fetch_sub(1) == 1) releaseBlock(blocks[b], extrasStride, *release);
    if (writing) {
      writing->advance(1);
    } else {
      reportProgress("tiles", ++done);
    }
  });
  for (const Status& f : written) LODFORGE_TRY(f);
  LODFORGE_TRY(checkCancelled());
  if (writing) writing->finish();
  return ContentsWritten{mine.size(), kept.load()};
}

// tileset.json: ADD refinement; a tile at depth d stands for the cut at τ_d, a block's tile for
// every point (τ = 0); the root placed by the local frame or --origin. Quantised positions
// move each point by up to half a step of its tile's grid on each axis: a tile's error adds that
// of the largest box showing points with it (the root's, its ancestors' boxes hold its own)
// for the shown point, and its own for the dropped one as the finer tiles show it. The same
// for every tile under one root, so errors still never grow from parent to child.
Status writePointTilesetJson(const std::map<std::string, TileNode>& nodes,
                             std::span<const BlockTiles> blocks, const std::vector<float>& taus,
                             const std::optional<Mat4d>& rootTransform, bool quantized,
                             const std::string& path) {
  float rootError = 0;
  for (const BlockTiles& b : blocks) rootError = std::max(rootError, b.rootError);
  const auto stepError = [&](const TileNode& node) {
    return quantized ? glbQuantizationError(node.bounds) : 0.0;
  };
  const double shownError = stepError(nodes.at("b"));
  const std::function<nlohmann::json(const TileNode&)> tile = [&](const TileNode& node) {
    const bool leaf = node.children.empty();
    const double tau = leaf ? 0.0 : static_cast<double>(taus[static_cast<std::size_t>(node.depth)]);
    nlohmann::json t = {{"boundingVolume", {{"box", tileBox(node.bounds)}}},
                        {"geometricError", tau + shownError + stepError(node)}};
    if (!node.uri.empty()) t["content"] = {{"uri", node.uri}};
    if (!leaf) {
      t["children"] = nlohmann::json::array();
      for (const std::string& child : node.children) t["children"].push_back(tile(nodes.at(child)));
    }
    return t;
  };
  nlohmann::json root = tile(nodes.at("b"));
  root["refine"] = "ADD";
  if (rootTransform) root["transform"] = rootTransform->m;
  const nlohmann::json tileset = {
      {"asset", {{"version", "1.1"}, {"generator", "lodforge " LODFORGE_VERSION}}},
      {"geometricError", std::max(static_cast<double>(rootError),
                                  taus.empty() ? 0.0 : 2.0 * static_cast<double>(taus.front()))},
      {"root", root}};
  return OutputFile::writeWhole(path, tileset.dump() + '\n');  // compact, as for meshes
}

// What the partition read into the stats: counts, attributes, warnings (one more when the tiles
// carry more vertex attributes than WebGL viewers draw), the deepest block.
void noteStats(const Partition& partition, const PointTilesOptions& options,
               PointTilesStats& stats) {
  stats.points = partition.pointCount;
  stats.attributes = partition.info.attributes & options.attributes;
  stats.warnings = partition.info.warnings;
  if (partition.truncation)
    stats.warnings.push_back(*partition.truncation + "; built from what came before");
  if (const std::size_t count = vertexAttributeCount(partition.info, stats.attributes);
      count > kViewerVertexAttributes)
    stats.warnings.push_back(fmt::format(
        "the tiles carry {} vertex attributes; WebGL viewers (CesiumJS, three.js) draw at most "
        "{}: choose fewer with --attributes",
        count, kViewerVertexAttributes));
  stats.blocks = partition.blocks.size();
  for (const PointBlock& b : partition.blocks) stats.depth = std::max(stats.depth, depthOf(b));
}

// Where the root sits on Earth: the local frame of the CRS, or --origin's; none without either.
std::optional<Mat4d> rootTransformOf(const std::optional<CrsToLocal>& frame,
                                     const PointTilesOptions& options) {
  if (frame) return frame->localToEcef();
  if (options.origin) return eastNorthUpToEcef(*options.origin);
  return std::nullopt;
}

PartitionOptions pointPartitionOptions(const PointTilesOptions& options,
                                       const PointMemoryPlan& plan,
                                       const std::optional<CrsToLocal>& frame,
                                       const std::string& workDirectory) {
  PartitionOptions partition;
  partition.blockSize = options.blockSize;
  partition.workDirectory = workDirectory;
  partition.salvageTruncated = options.salvageTruncated;
  partition.carryExtras = (options.attributes & kAttrExtras) != 0;
  // rankBlock's clustering gives every point a normal; quantised tiles only draw it, as bytes.
  partition.normals = options.quantize ? RecordNormals::kBytes : RecordNormals::kFloat;
  partition.memoryBytes = plan.partitionBytes;
  // The tests' knob: nodes of a few points, so that a small cloud has several to share out.
  if (const char* bytes = std::getenv("LODFORGE_PARTITION_BYTES"))
    partition.memoryBytes = std::strtoull(bytes, nullptr, 10);
  if (frame) partition.transform = [&frame](Vec3d in, Vec3d& out) { return frame->apply(in, out); };
  return partition;
}

std::string pointWorkDirectory(const std::string& outputDirectory) {
  return tilesWorkDirectory(outputDirectory) + "/points";
}

PointWorkScope::~PointWorkScope() {
  if (!finished && !work.empty() && pointWorkKept(work)) directory.path.clear();
}

Status resetPointWork(const std::string& workDirectory) {
  std::error_code error;
  fs::remove_all(workDirectory, error);
  if (!error) fs::create_directories(workDirectory + "/tileset/tiles", error);
  if (!error) fs::create_directories(workDirectory + "/nodes", error);
  if (error) return ioError(workDirectory, fmt::format("cannot create: {}", error.message()));
  return {};
}

Status claimPointWorkPlace(const std::string& input, const std::string& outputDirectory,
                           bool resume, WorkLock& lock, PointWorkScope& scope) {
  LODFORGE_TRY(claimTilesetOutput(input, outputDirectory));
  const std::string workDirectory = tilesWorkDirectory(outputDirectory);
  const std::string work = pointWorkDirectory(outputDirectory);
  // Another run's work kept there (an interrupted mesh run's, for --resume) stays; our own
  // folder, and an earlier point run's unless resuming, go.
  std::error_code error;
  bool othersWork = false;
  for (fs::directory_iterator entry(workDirectory, error), end; !error && entry != end;
       entry.increment(error)) {
    const std::string name = entry->path().filename().string();
    othersWork = othersWork || (name != "points" && !name.starts_with(".lodforge-"));
  }
  LODFORGE_TRY(claimWorkDirectory(workDirectory));
  Result<WorkLock> locked = lockWorkDirectory(workDirectory);
  if (!locked) return locked.status();
  lock = std::move(*locked);
  scope.directory.path = othersWork ? work : workDirectory;
  scope.work = work;
  if (!resume) return resetPointWork(work);
  removeOutputTemporaries(work + "/tileset");
  return {};
}

}  // namespace lodforge
