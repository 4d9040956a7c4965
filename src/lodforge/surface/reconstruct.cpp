#include "lodforge/surface/reconstruct.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <queue>

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/surface/chunk_runs.h"
#include "lodforge/surface/cloud_file.h"
#include "lodforge/surface/layout.h"
#include "lodforge/surface/mesh_join.h"
#include "lodforge/surface/point_index.h"

namespace lodforge {

namespace {

// Bytes a point costs when normals are turned by propagation over the whole cloud: position,
// normal, the k nearest (k = 12) and the symmetric neighbour graph.
constexpr std::uint64_t kBytesPerPropagatedPoint = 24 + 12 + 12 * 4 * 3;
// Bytes of one chunk in flight per corner: the weight and sum (doubles), offsets and
// directions (floats), count and value.
constexpr std::uint64_t kBytesPerCorner = 8 + 8 + 12 + 12 + 4 + 4;
// Bytes a point of a run costs: its record, its places in the chunks' lists, and the gathered
// copies of the chunks in flight with their k-d trees for colours.
constexpr std::uint64_t kBytesPerRunPoint = 48 + 8 + 44 + 40;
// What the rest holds besides the runs and the grids (the join's wavefront, buffers).
constexpr std::uint64_t kOtherBytes = std::uint64_t{48} << 20;

// A chunk is computed with one corner of margin round it, for the gradient at its faces.
std::uint64_t gridBytes(std::uint32_t n) {
  const std::uint64_t side = std::uint64_t{n} + 3;
  return side * side * side * kBytesPerCorner;
}

int threads() {
  return std::max(1, tbb::this_task_arena::max_concurrency());
}

Status checkChunkFits(const ChunkLayout& layout, const ReconstructOptions& options,
                      const std::string& name) {
  const std::uint64_t grids = gridBytes(layout.n) * static_cast<std::uint64_t>(threads());
  if (options.memoryLimit > 0 && grids > options.memoryLimit / 2)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: {} chunks of {}³ voxels in flight need {} of grid, more than "
                             "half of --memory-limit {}: use a smaller --chunk-size",
                             name, threads(), layout.n, formatBytes(grids),
                             formatBytes(options.memoryLimit))};
  return {};
}

std::uint64_t runBudget(const ChunkLayout& layout, const ReconstructOptions& options) {
  if (options.runPoints > 0) return options.runPoints;
  if (options.memoryLimit == 0) return kDefaultRunPoints;
  const std::uint64_t grids = gridBytes(layout.n) * static_cast<std::uint64_t>(threads());
  const std::uint64_t left =
      options.memoryLimit > grids + kOtherBytes ? options.memoryLimit - grids - kOtherBytes : 0;
  return std::max<std::uint64_t>(10'000, left / kBytesPerRunPoint);
}

double voxelFor(const ReconstructOptions& options, double spacing) {
  return options.voxel > 0 ? options.voxel : 2 * spacing;
}

std::uint32_t chunkVoxelsFor(const ReconstructOptions& options, double voxel) {
  if (options.chunkLength <= 0) return options.chunkVoxels;
  const double n = std::round(options.chunkLength / voxel);
  return static_cast<std::uint32_t>(std::clamp(n, 4.0, 4096.0));
}

// The members of each of the run's chunks (ascending), by index into `records`, in input order.
// The reach is a voxel more than the radius: the corners of a chunk's margin need their points.
std::vector<std::vector<std::uint32_t>> membersOf(const ChunkLayout& layout,
                                                  std::span<const CloudRecord> records,
                                                  std::span<const std::uint64_t> chunks,
                                                  double radius) {
  std::vector<std::vector<std::uint32_t>> members(chunks.size());
  for (std::uint32_t i = 0; i < records.size(); ++i) {
    const ChunkBox box = layout.reach(records[i].position, radius + 1);
    for (std::uint64_t z = box.lo[2]; z <= box.hi[2]; ++z)
      for (std::uint64_t y = box.lo[1]; y <= box.hi[1]; ++y)
        for (std::uint64_t x = box.lo[0]; x <= box.hi[0]; ++x) {
          const std::uint64_t c = layout.chunkIndex(x, y, z);
          const auto at = std::lower_bound(chunks.begin(), chunks.end(), c);
          if (at != chunks.end() && *at == c)
            members[static_cast<std::size_t>(at - chunks.begin())].push_back(i);
        }
  }
  return members;
}

// One chunk's piece: distances at its corners and a corner of margin, polygonized within its
// own corners; a vertex's colour is its nearest member's (the chunk's members do not depend on
// how chunks are cut into runs, so neither do the colours).
SurfacePiece chunkPiece(const ChunkLayout& layout, std::uint64_t c,
                        std::span<const std::uint32_t> members,
                        std::span<const CloudRecord> records, const DistanceOptions& distance,
                        bool colors) {
  std::vector<Vec3d> p(members.size());
  std::vector<Vec3f> nrm(members.size());
  std::vector<std::uint64_t> ids(members.size());
  for (std::size_t m = 0; m < members.size(); ++m) {
    p[m] = records[members[m]].position;
    ids[m] = records[members[m]].id;
  }
  // In the order every chunk adds a corner's points (implicit.h), nearby points together.
  const std::vector<std::uint32_t> order = sumOrder(layout.grid, p, ids);
  std::vector<std::uint32_t> sorted(members.size());
  for (std::size_t m = 0; m < members.size(); ++m) {
    sorted[m] = members[order[m]];
    const CloudRecord& r = records[sorted[m]];
    p[m] = r.position;
    nrm[m] = r.normal;
    ids[m] = r.id;
  }
  const std::array<std::uint64_t, 3> at = layout.chunkAt(c);
  std::array<std::uint64_t, 3> first{};
  std::array<std::uint32_t, 3> size{};
  CornerValues values;
  for (std::size_t a = 0; a < 3; ++a) {
    first[a] = at[a] * layout.n;
    size[a] = static_cast<std::uint32_t>(
        std::min<std::uint64_t>(layout.n + 1, layout.grid.corners[a] - first[a]));
    values.first[a] = first[a] > 0 ? first[a] - 1 : 0;
    values.size[a] = static_cast<std::uint32_t>(
        std::min<std::uint64_t>(first[a] + size[a] + 1, layout.grid.corners[a]) - values.first[a]);
  }
  signedDistances(layout.grid, {p, nrm, ids}, distance, values);
  SurfacePiece piece = polygonize(layout.grid, values, first, size);
  if (colors && !piece.positions.empty()) {
    const PointIndex index(p);
    piece.colors.resize(piece.positions.size());
    for (std::size_t v = 0; v < piece.positions.size(); ++v) {
      std::uint32_t nearest = 0;
      double d2 = 0;
      index.nearest(piece.positions[v], 1, &nearest, &d2);
      piece.colors[v] = records[sorted[nearest]].color;
    }
  }
  return piece;
}

// The run's chunks made a few per thread at a time and handed on in chunk order.
Status makeChunks(const ChunkLayout& layout, std::span<const CloudRecord> records,
                  std::span<const std::uint64_t> chunks, const ReconstructOptions& options,
                  bool colors, PieceSink& sink, Progress& progress,
                  std::vector<SurfacePiece>* pieces) {
  const std::vector<std::vector<std::uint32_t>> members =
      membersOf(layout, records, chunks, options.distance.radius);
  const auto batch = static_cast<std::size_t>(4 * threads());
  std::vector<SurfacePiece> made(batch);
  for (std::size_t first = 0; first < chunks.size(); first += batch) {
    const std::size_t last = std::min(chunks.size(), first + batch);
    tbb::parallel_for(first, last, [&](std::size_t i) {
      made[i - first] = members[i].empty() ? SurfacePiece{}
                                           : chunkPiece(layout, chunks[i], members[i], records,
                                                        options.distance, colors);
    });
    for (std::size_t i = first; i < last; ++i) {
      LODFORGE_TRY(sink.add(chunks[i], made[i - first]));
      if (pieces) pieces->push_back(std::move(made[i - first]));
      made[i - first] = SurfacePiece{};
    }
    progress.advance(last - first);
    LODFORGE_TRY(checkCancelled());
  }
  return {};
}

// Normals turned by propagation need the whole cloud's neighbour graph at once.
Status checkPropagationFits(std::uint64_t points, const ReconstructOptions& options,
                            const std::string& name) {
  if (options.memoryLimit > 0 && points * kBytesPerPropagatedPoint > options.memoryLimit)
    return Error{
        ErrorKind::kLimit,
        fmt::format("{}: turning the normals of {} points by propagation needs about {}, "
                    "more than --memory-limit {}: give --orient up or --orient X,Y,Z "
                    "(estimated chunk by chunk), or points with normals",
                    name, formatCount(points), formatBytes(points * kBytesPerPropagatedPoint),
                    formatBytes(options.memoryLimit))};
  return {};
}

// Propagation: the positions in memory, the normals written back into the record file.
Status estimateNormalsWhole(const std::string& cloudPath, const CloudSummary& cloud,
                            const NormalOptions& options) {
  std::vector<Vec3d> positions;
  positions.reserve(static_cast<std::size_t>(cloud.count));
  LODFORGE_TRY(forEachRecordBlock(cloudPath, [&](std::span<const CloudRecord> block) {
    for (const CloudRecord& r : block) positions.push_back(r.position);
    return Status{};
  }));
  std::vector<Vec3f> normals;
  {
    const PointIndex index(positions);
    normals = estimateNormals(positions, index, options);
  }
  return rewriteNormals(cloudPath, [&](std::span<CloudRecord> block) {
    for (CloudRecord& r : block) r.normal = normals[static_cast<std::size_t>(r.id)];
    return Status{};
  });
}

struct OwnedNormal {
  std::uint64_t id;
  Vec3f normal;
  std::uint32_t unused = 0;
};

// A run's owned normals, read back in id order.
class NormalStream {
 public:
  explicit NormalStream(std::FILE* file) : file_(file) { refill(); }
  NormalStream(const NormalStream&) = delete;
  NormalStream& operator=(const NormalStream&) = delete;
  ~NormalStream() { std::fclose(file_); }
  bool done() const { return at_ == got_; }
  const OwnedNormal& head() const { return block_[at_]; }
  void pop() {
    if (++at_ == got_) refill();
  }

 private:
  void refill() {
    got_ = std::fread(block_.data(), sizeof(OwnedNormal), block_.size(), file_);
    at_ = 0;
  }
  std::FILE* file_;
  std::vector<OwnedNormal> block_ = std::vector<OwnedNormal>(4096);
  std::size_t at_ = 0, got_ = 0;
};

std::string normalsPath(const std::string& directory, std::size_t run) {
  return fmt::format("{}/run-{}.normals", directory, run);
}

// Up or towards a viewpoint: each point's normal from its neighbours in the run that owns it
// (the run of the chunk it lies in), so a normal is computed once; then merged into the record
// file in id order.
Status estimateNormalsByRun(const std::string& cloudPath, const ChunkLayout& layout,
                            const ChunkRuns& runs, const ReconstructOptions& options,
                            const std::string& directory) {
  LODFORGE_TRY(writeRuns(cloudPath, layout, options.distance.radius + 1, runs, directory));
  Progress progress("reconstruct: normals", runs.runCount());
  for (std::size_t r = 0; r < runs.runCount(); ++r) {
    Result<std::vector<CloudRecord>> records = readRecords(runPath(directory, r));
    if (!records) return records.status();
    std::remove(runPath(directory, r).c_str());
    std::vector<Vec3d> positions(records->size());
    for (std::size_t i = 0; i < positions.size(); ++i) positions[i] = (*records)[i].position;
    std::vector<Vec3f> normals;
    {
      const PointIndex index(positions);
      normals = estimateNormals(positions, index, options.normals);
    }
    Result<OutputFile> out = OutputFile::create(normalsPath(directory, r), 1 << 20);
    if (!out) return out.status();
    for (std::size_t i = 0; i < positions.size(); ++i) {
      if (runs.runOf(layout.owner(positions[i])) != r) continue;
      const OwnedNormal owned{(*records)[i].id, normals[i]};
      LODFORGE_TRY(out->write(&owned, sizeof owned));
    }
    LODFORGE_TRY(out->commit());
    progress.advance(1);
    LODFORGE_TRY(checkCancelled());
  }
  progress.finish();
  std::vector<std::unique_ptr<NormalStream>> streams;
  for (std::size_t r = 0; r < runs.runCount(); ++r) {
    std::FILE* file = std::fopen(normalsPath(directory, r).c_str(), "rb");
    if (!file) return ioErrorFromErrno(normalsPath(directory, r), "open");
    streams.push_back(std::make_unique<NormalStream>(file));
  }
  using Head = std::pair<std::uint64_t, std::size_t>;  // (id, run)
  std::priority_queue<Head, std::vector<Head>, std::greater<>> heads;
  for (std::size_t r = 0; r < streams.size(); ++r)
    if (!streams[r]->done()) heads.emplace(streams[r]->head().id, r);
  LODFORGE_TRY(rewriteNormals(cloudPath, [&](std::span<CloudRecord> block) -> Status {
    for (CloudRecord& record : block) {
      if (heads.empty() || heads.top().first != record.id)
        return Error{ErrorKind::kInternal,
                     fmt::format("{}: point {} has no normal", cloudPath, record.id)};
      const std::size_t run = heads.top().second;
      heads.pop();
      NormalStream& s = *streams[run];
      record.normal = s.head().normal;
      s.pop();
      if (!s.done()) heads.emplace(s.head().id, run);
    }
    return Status{};
  }));
  return {};
}

}  // namespace

Result<ReconstructStats> reconstructPieces(const std::string& input,
                                           const std::string& workDirectory,
                                           const ReconstructOptions& options, PieceSink& sink) {
  const std::string cloudPath = workDirectory + "/cloud.points";
  Result<CloudSummary> cloud =
      copyCloud(input, cloudPath, options.salvageTruncated, options.transform);
  if (!cloud) return cloud.status();
  LODFORGE_TRY(checkSurfaceExtent(cloud->count, cloud->bounds, input));
  double spacing = 0;
  if (options.voxel <= 0) {
    Result<double> measured = medianSpacingOfFile(cloudPath, *cloud);
    if (!measured) return measured.status();
    spacing = *measured;
  }
  const double voxel = voxelFor(options, spacing);
  Result<ChunkLayout> layout = layOutChunks(cloud->bounds, voxel, chunkVoxelsFor(options, voxel),
                                            options.distance.radius, input);
  if (!layout) return layout.status();
  LODFORGE_TRY(checkChunkFits(*layout, options, input));
  ReconstructStats stats;
  stats.grid = layout->grid;
  stats.chunkVoxels = layout->n;
  stats.points = cloud->count;
  stats.chunks = layout->chunkCount();
  stats.hasColors = cloud->hasColors;
  const double reach = options.distance.radius + 1;
  Result<ChunkRuns> runs = planRuns(cloudPath, *layout, reach, runBudget(*layout, options));
  if (!runs) return runs.status();
  stats.runs = runs->runCount();
  if (!cloud->hasNormals) {
    stats.estimatedNormals = true;
    if (options.normals.orientation == NormalOrientation::kPropagate) {
      LODFORGE_TRY(checkPropagationFits(cloud->count, options, input));
      LODFORGE_TRY(estimateNormalsWhole(cloudPath, *cloud, options.normals));
    } else {
      LODFORGE_TRY(estimateNormalsByRun(cloudPath, *layout, *runs, options, workDirectory));
    }
  }
  LODFORGE_TRY(writeRuns(cloudPath, *layout, reach, *runs, workDirectory));
  std::error_code error;
  std::filesystem::remove(cloudPath, error);
  LODFORGE_TRY(sink.begin(*layout, cloud->hasColors));
  Progress progress("reconstruct: chunks", runs->chunks.size());
  for (std::size_t r = 0; r < runs->runCount(); ++r) {
    Result<std::vector<CloudRecord>> records = readRecords(runPath(workDirectory, r));
    if (!records) return records.status();
    std::filesystem::remove(runPath(workDirectory, r), error);
    const std::span<const std::uint64_t> chunks(runs->chunks.data() + runs->firstChunk[r],
                                                runs->firstChunk[r + 1] - runs->firstChunk[r]);
    LODFORGE_TRY(
        makeChunks(*layout, *records, chunks, options, cloud->hasColors, sink, progress, nullptr));
  }
  progress.finish();
  return stats;
}

Status noSurface(const std::string& input, double voxel) {
  return badInput(input, fmt::format("no surface at voxel {:g}: the points are too sparse for it "
                                     "(try a larger --voxel or --radius, or a smaller "
                                     "--min-points)",
                                     voxel));
}

Result<ReconstructStats> reconstructToFile(const std::string& input, const std::string& output,
                                           const ReconstructOptions& options) {
  ScopedDirectory work(temporaryPathFor(output + ".work"));
  std::error_code error;
  std::filesystem::create_directories(work.path, error);
  if (error) return ioError(work.path, fmt::format("cannot create: {}", error.message()));
  Result<std::unique_ptr<PlyMeshOutput>> mesh = PlyMeshOutput::create(work.path);
  if (!mesh) return mesh.status();
  PieceJoiner joiner(options.minTriangles, **mesh);
  Result<ReconstructStats> stats = reconstructPieces(input, work.path, options, joiner);
  if (!stats) return stats;
  stats->vertices = joiner.vertices();
  stats->triangles = joiner.triangles();
  stats->droppedPieces = joiner.droppedPieces();
  if (stats->triangles == 0) return noSurface(input, stats->grid.voxel);
  LODFORGE_TRY((*mesh)->finish(output, stats->hasColors, "lodforge reconstruct"));
  return stats;
}

Result<ReconstructedMesh> reconstructPoints(std::vector<Vec3d> positions,
                                            std::vector<Vec3f> normals, std::vector<Rgba8> colors,
                                            const std::string& name,
                                            const ReconstructOptions& options,
                                            std::vector<SurfacePiece>* pieces) {
  Aabbd bounds;
  for (const Vec3d& p : positions) bounds.add(p);
  LODFORGE_TRY(checkSurfaceExtent(positions.size(), bounds, name));
  std::optional<PointIndex> index;
  if (options.voxel <= 0 || normals.empty()) index.emplace(positions);
  const double spacing = options.voxel > 0 ? 0 : medianSpacing(positions, *index);
  const double voxel = voxelFor(options, spacing);
  Result<ChunkLayout> layout =
      layOutChunks(bounds, voxel, chunkVoxelsFor(options, voxel), options.distance.radius, name);
  if (!layout) return layout.status();
  LODFORGE_TRY(checkChunkFits(*layout, options, name));
  ReconstructedMesh mesh;
  mesh.grid = layout->grid;
  mesh.chunkVoxels = layout->n;
  mesh.points = positions.size();
  mesh.chunks = layout->chunkCount();
  mesh.runs = 1;
  mesh.hasColors = !colors.empty();
  if (normals.empty()) {
    normals = estimateNormals(positions, *index, options.normals);
    mesh.estimatedNormals = true;
  }
  index.reset();
  std::vector<CloudRecord> records(positions.size());
  for (std::size_t i = 0; i < records.size(); ++i)
    records[i] = {i, positions[i], normalizeOr(normals[i], Vec3f{0, 0, 1}),
                  colors.empty() ? Rgba8{} : colors[i]};
  std::vector<std::uint64_t> chunks;
  for (const CloudRecord& r : records) {
    const ChunkBox box = layout->reach(r.position, options.distance.radius + 1);
    for (std::uint64_t z = box.lo[2]; z <= box.hi[2]; ++z)
      for (std::uint64_t y = box.lo[1]; y <= box.hi[1]; ++y)
        for (std::uint64_t x = box.lo[0]; x <= box.hi[0]; ++x)
          chunks.push_back(layout->chunkIndex(x, y, z));
  }
  std::sort(chunks.begin(), chunks.end());
  chunks.erase(std::unique(chunks.begin(), chunks.end()), chunks.end());
  MemoryMeshOutput out;
  PieceJoiner joiner(options.minTriangles, out);
  LODFORGE_TRY(joiner.begin(*layout, !colors.empty()));
  Progress progress("reconstruct: chunks", chunks.size());
  LODFORGE_TRY(
      makeChunks(*layout, records, chunks, options, !colors.empty(), joiner, progress, pieces));
  progress.finish();
  mesh.vertices = joiner.vertices();
  mesh.triangles = joiner.triangles();
  mesh.droppedPieces = joiner.droppedPieces();
  mesh.positions = std::move(out.positions);
  mesh.normals = std::move(out.normals);
  if (!colors.empty()) mesh.colors = std::move(out.colors);
  mesh.indices = std::move(out.indices);
  return mesh;
}

}  // namespace lodforge
