#include "lodforge/tiles/point_tiles.h"

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

// One block, ranked while the partition holds it in memory: its points sorted by their key,
// highest first, in `path` and the keys in `keysPath`. A point's key is the tile error of the
// parent of the highest node it represents (+∞ for the root's): the cut at τ holds the point
// exactly when τ < key, so a tile at depth d (tolerance τ_d, non-increasing with d) holds a
// prefix of the sorted block whatever the τ turn out to be.
struct BlockTiles {
  std::string path, keysPath;  // the partition's work file (from `first` on), the keys
  PointRecordLayout layout;    // of the work file's records
  std::uint64_t first = 0;
  std::vector<std::uint64_t> counts;  // per depth 0..depthOf(block), once the τ are known
  Aabbd bounds;
  float rootError = 0;
  float leastError = 0;  // the least tile error in the block's tree
};

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

// Sorts the block's points by key (the partition writes them back in that order) and writes
// the keys beside.
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
  out.path = block.path;
  out.layout = block.layout;
  out.first = block.first;
  out.keysPath = workDirectory + "/" + block.name + ".keys";
  out.bounds = block.bounds;
  out.rootError = tree.front().error;
  Result<OutputFile> keys = OutputFile::create(out.keysPath, std::size_t{1} << 20);
  if (!keys) return keys.status();
  LODFORGE_TRY(keys->writeSpan(std::span<const float>(key)));
  return keys->commit();
}

Result<std::vector<float>> readKeys(const BlockTiles& block, std::uint64_t count) {
  Result<ByteSource> in = ByteSource::openFile(block.keysPath);
  if (!in) return in.status();
  std::vector<float> keys(count);
  if (!in->read(keys.data(), keys.size() * sizeof(float)))
    return ioError(block.keysPath, "work file is shorter than expected");
  return keys;
}

// The least τ of the block's tree whose cut holds at most `budget` points: the (budget + 1)-th
// key (toleranceForResident over the tree, from the keys alone).
float toleranceForBudget(std::span<const float> keys, const BlockTiles& block, std::size_t budget) {
  if (budget >= keys.size()) return block.leastError;
  return std::min(keys[budget], block.rootError);
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
    std::error_code ignored;
    fs::remove(blocks[b].keysPath, ignored);
  });
  for (const Status& f : failures) LODFORGE_TRY(f);
  return Status{};
}

struct TileNode {
  std::string name;
  int depth = 0;
  std::vector<std::size_t> blocks;    // under it
  std::vector<std::string> children;  // names
  Aabbd bounds;
  std::uint64_t points = 0;  // in its own content
  std::string uri;           // empty when it has no content
};

// What a tile's GLB carries besides positions and normals: colours, the lidar attributes and
// the extra fields (from their work file).
struct ContentFields {
  bool colors = false;
  std::uint32_t attributes = 0;  // PointAttributeBit
  const PointExtras* extras = nullptr;
  std::string extrasPath;
};

Status writeContent(const TileNode& node, std::span<const BlockTiles> blocks,
                    const PointTilesOptions& options, ContentFields fields,
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
        readExtraRecords(fields.extrasPath, fields.extras->stride, first, block.counts[d]);
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
std::map<std::string, TileNode> tileTree(const Partition& partition,
                                         const std::vector<BlockTiles>& blocks) {
  std::map<std::string, TileNode> nodes;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const std::string& name = partition.blocks[b].name;
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

// The GLB of every tile with points, in parallel; how many were written.
Result<std::uint64_t> writeContents(std::map<std::string, TileNode>& nodes,
                                    const std::vector<BlockTiles>& blocks,
                                    const PointTilesOptions& options, ContentFields fields,
                                    const std::string& tilesetDirectory) {
  std::vector<TileNode*> withContent;
  for (auto& [name, node] : nodes)
    if (!node.uri.empty()) withContent.push_back(&node);
  std::vector<Status> written(withContent.size());
  Progress writing("tiles: contents", withContent.size());
  tbb::parallel_for(std::size_t{0}, withContent.size(), [&](std::size_t i) {
    if (cancelRequested()) return;
    written[i] = writeContent(*withContent[i], blocks, options, fields,
                              tilesetDirectory + "/" + withContent[i]->uri);
    writing.advance(1);
  });
  for (const Status& f : written) LODFORGE_TRY(f);
  LODFORGE_TRY(checkCancelled());
  writing.finish();
  return withContent.size();
}

// tileset.json: ADD refinement; a tile at depth d stands for the cut at τ_d, a block's tile for
// every point (τ = 0); the root placed by the local frame or --origin. Quantised positions
// move each point by up to half a step of its tile's grid on each axis: a tile's error adds that
// of the largest box showing points with it (the root's, its ancestors' boxes hold its own)
// for the shown point, and its own for the dropped one as the finer tiles show it. The same
// for every tile under one root, so errors still never grow from parent to child.
Status writePointTilesetJson(const std::map<std::string, TileNode>& nodes,
                             const std::vector<BlockTiles>& blocks, const std::vector<float>& taus,
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
  PartitionOptions partitionOptions;
  partitionOptions.blockSize = options.blockSize;
  partitionOptions.workDirectory = workDirectory;
  partitionOptions.salvageTruncated = options.salvageTruncated;
  partitionOptions.carryExtras = (options.attributes & kAttrExtras) != 0;
  // rankBlock's clustering gives every point a normal; quantised tiles only draw it, as bytes.
  partitionOptions.normals = options.quantize ? RecordNormals::kBytes : RecordNormals::kFloat;
  partitionOptions.memoryBytes = plan.partitionBytes;
  if (frame)
    partitionOptions.transform = [&frame](Vec3d in, Vec3d& out) { return frame->apply(in, out); };
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
  for (const PointBlock& b : out.partition.blocks)
    out.blocks.push_back(std::move(byName.at(b.name)));
  return out;
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

}  // namespace

Result<PointTilesStats> writePointTiles(const std::string& input,
                                        const std::string& outputDirectory,
                                        const PointTilesOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PointTilesStats stats;
  LODFORGE_TRY(claimTilesetOutput(input, outputDirectory));
  Result<PointMemoryPlan> plan = planPointMemory(options.memoryLimit, options.blockSize);
  if (!plan) return plan.status();
  // A fresh work directory of our own (nothing to resume) that also stages the tileset.
  ScopedDirectory work(temporaryPathFor(outputDirectory + ".work"));
  ScopedDirectory staging(work.path + "/tileset");
  std::error_code error;
  fs::create_directories(fs::path(staging.path) / "tiles", error);
  if (error) return ioError(work.path, fmt::format("cannot create: {}", error.message()));

  bool hasNormals = false;
  Result<std::optional<CrsToLocal>> frame = localFrame(input, options, stats, hasNormals);
  if (!frame) return frame.status();
  Result<RankedPartition> ranked =
      partitionAndRank(input, options, *plan, *frame, hasNormals, work.path);
  if (!ranked) return ranked.status();
  const Partition& partition = ranked->partition;
  std::vector<BlockTiles>& blocks = ranked->blocks;
  noteStats(partition, options, stats);
  Result<std::vector<float>> taus = toleranceSchedule(partition, blocks, options, stats.depth);
  if (!taus) return taus.status();
  LODFORGE_TRY(countLevels(partition, *taus, blocks));

  std::map<std::string, TileNode> nodes = tileTree(partition, blocks);
  Result<std::uint64_t> tiles =
      writeContents(nodes, blocks, options,
                    {partition.info.hasColors, partition.info.attributes & options.attributes,
                     &partition.info.extras, partition.extrasPath},
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
