#include "lodforge/surface/reconstruct_steps.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/units.h"
#include "lodforge/surface/chunk_piece.h"
#include "lodforge/surface/normals.h"
#include "lodforge/surface/piece_decimation.h"
#include "lodforge/surface/point_index.h"

namespace lodforge {

namespace {

// Bytes a point costs when normals are turned by propagation over the whole cloud: position,
// normal, the k nearest (k = 12) and the symmetric neighbour graph.
constexpr std::uint64_t kBytesPerPropagatedPoint = 24 + 12 + 12 * 4 * 3;

// Bytes of one chunk in flight per corner: the weight and sum (doubles), offsets and
// directions (floats), count and value.
constexpr std::uint64_t kBytesPerCorner = 8 + 8 + 12 + 12 + 4 + 4;

// Bytes a point of a run costs: its record, its places in the chunks' lists, the gathered
// copies of the chunks in flight with their k-d trees for colours, and its point cell in the
// chunks' sums (a hash node, when every point has a cell of its own).
constexpr std::uint64_t kBytesPerRunPoint = 48 + 8 + 44 + 40 + 112;

// What the rest holds besides the runs and the grids (the join's wavefront, buffers).
constexpr std::uint64_t kOtherBytes = std::uint64_t{48} << 20;

}  // namespace

bool isDenseRun(const ChunkRuns& runs, std::size_t r, std::uint64_t budget) {
  return runs.firstChunk[r + 1] - runs.firstChunk[r] == 1 &&
         runs.points[runs.firstChunk[r]] > budget;
}

namespace {

// A chunk is computed with one corner of margin round it, for the gradient at its faces.
std::uint64_t gridBytes(std::uint32_t n) {
  const std::uint64_t side = std::uint64_t{n} + 3;
  return side * side * side * kBytesPerCorner;
}

int threads() {
  return std::max(1, tbb::this_task_arena::max_concurrency());
}

}  // namespace

Status checkChunkFits(const ChunkLayout& layout, const ReconstructOptions& options,
                      const std::string& name) {
  const std::uint64_t grids = gridBytes(layout.n) * static_cast<std::uint64_t>(threads());
  // A limit too small is a limit (exit 1), as in every command, with the least that works.
  if (options.memoryLimit > 0 && grids > options.memoryLimit / 2)
    return Error{ErrorKind::kLimit,
                 fmt::format("{}: {} chunks of {}³ voxels in flight need {} of grid, more than "
                             "half of --memory-limit {}: give at least --memory-limit {}, or a "
                             "smaller --chunk-size",
                             name, threads(), layout.n, formatBytes(grids),
                             formatBytes(options.memoryLimit), formatBytes(2 * grids))};
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

double voxelFor(const ReconstructOptions& options, double spacing, double unitScale) {
  return options.voxel > 0 ? options.voxel * unitScale : 2 * spacing;
}

std::uint32_t chunkVoxelsFor(const ReconstructOptions& options, double voxel, double unitScale) {
  if (options.chunkLength <= 0) return options.chunkVoxels;
  const double n = std::round(options.chunkLength * unitScale / voxel);
  return static_cast<std::uint32_t>(std::clamp(n, 4.0, 4096.0));
}

namespace {

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

}  // namespace

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
      made[i - first] = members[i].empty()
                            ? SurfacePiece{}
                            : decimatePiece(layout,
                                            heldChunkPiece(layout, chunks[i], members[i], records,
                                                           options.distance, colors),
                                            options.decimateVoxels * layout.grid.voxel);
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

namespace {

// A chunk streamed from its run file (chunk_piece.h).
Status streamDenseChunk(const ChunkLayout& layout, std::uint64_t chunk, const std::string& runFile,
                        const ReconstructOptions& options, bool colors, PieceSink& sink,
                        Progress& progress) {
  Result<SurfacePiece> piece = streamedChunkPiece(layout, chunk, runFile, options.distance, colors);
  if (!piece) return piece.status();
  LODFORGE_TRY(sink.add(
      chunk, decimatePiece(layout, std::move(*piece), options.decimateVoxels * layout.grid.voxel)));
  progress.advance(1);
  return checkCancelled();
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

std::string normalsPath(const std::string& directory, std::size_t run) {
  return fmt::format("{}/run-{}.normals", directory, run);
}

// The normals of `records` from their neighbours among them; those of the points `owns` accepts
// written to `path` in input order.
template <class Owns>
Result<OwnedNormalFile> writeOwnedNormals(std::span<const CloudRecord> records,
                                          const NormalOptions& options, Owns&& owns,
                                          const std::string& path) {
  std::vector<Vec3d> positions(records.size());
  for (std::size_t i = 0; i < positions.size(); ++i) positions[i] = records[i].position;
  std::vector<Vec3f> normals;
  {
    const PointIndex index(positions);
    normals = estimateNormals(positions, index, options);
  }
  Result<OutputFile> out = OutputFile::create(path, 1 << 20);
  if (!out) return out.status();
  OwnedNormalFile written{path, 0};
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!owns(positions[i])) continue;
    const OwnedNormal owned{records[i].id, normals[i]};
    LODFORGE_TRY(out->write(&owned, sizeof owned));
    ++written.records;
  }
  LODFORGE_TRY(out->commit());
  return written;
}

// How many part files one pass over a dense run file writes (buffers of 64 KiB each: 4 MiB).
constexpr std::uint64_t kPartFilesAtOnce = 64;

// The a × b parts across x and y a dense chunk's normals are estimated in (at most a voxel's
// column a part).
std::array<std::uint64_t, 2> denseCuts(const ChunkLayout& layout, std::uint64_t points,
                                       std::uint64_t budget) {
  const std::uint64_t parts = (2 * points + budget - 1) / budget;
  const std::uint64_t across = std::min<std::uint64_t>(
      layout.n, static_cast<std::uint64_t>(std::ceil(std::sqrt(static_cast<double>(parts)))));
  return {across, std::min<std::uint64_t>(layout.n, (parts + across - 1) / across)};
}

// A chunk denser than a run may hold, its normals in parts: its columns cut in a × b across x
// and y. The run file is split once (per kPartFilesAtOnce parts) into a file per part holding
// the part with the overlap round it (the runs' own, radius and a voxel); then each part's
// owned points' normals are written to a file of its own.
Status denseChunkNormals(const std::string& runFile, const ChunkLayout& layout, std::uint64_t chunk,
                         std::uint64_t points, std::uint64_t budget,
                         const ReconstructOptions& options, const std::string& partPath,
                         std::vector<OwnedNormalFile>& files) {
  const std::array<std::uint64_t, 2> cuts = denseCuts(layout, points, budget);
  const std::array<std::uint64_t, 3> at = layout.chunkAt(chunk);
  const double margin = options.distance.radius + 1;
  // A point's lattice coordinate along x (a = 0) or y, in the chunk.
  const auto inChunk = [&](const Vec3d& p, std::size_t a) {
    const int axis = static_cast<int>(a);
    return (p[axis] - layout.grid.origin[axis]) / layout.grid.voxel -
           static_cast<double>(at[a] * layout.n);
  };
  const auto partAt = [&](double g, std::size_t a) {
    const double part = std::floor(g * static_cast<double>(cuts[a]) / layout.n);
    return static_cast<std::uint64_t>(std::clamp(part, 0.0, static_cast<double>(cuts[a] - 1)));
  };
  const auto near = [&](double g, std::size_t a, std::uint64_t part) {
    const double width = static_cast<double>(layout.n) / static_cast<double>(cuts[a]);
    return g >= static_cast<double>(part) * width - margin &&
           g <= static_cast<double>(part + 1) * width + margin;
  };
  const std::uint64_t total = cuts[0] * cuts[1];
  const auto recordsPath = [&](std::uint64_t part) {
    return fmt::format("{}-{}-{}.records", partPath, part / cuts[1], part % cuts[1]);
  };
  for (std::uint64_t first = 0; first < total; first += kPartFilesAtOnce) {
    const std::uint64_t last = std::min(total, first + kPartFilesAtOnce);
    std::vector<RecordWriter> writers;
    for (std::uint64_t part = first; part < last; ++part) {
      Result<RecordWriter> writer = RecordWriter::create(recordsPath(part), 64 << 10);
      if (!writer) return writer.status();
      writers.push_back(std::move(*writer));
    }
    LODFORGE_TRY(forEachRecordBlock(runFile, [&](std::span<const CloudRecord> block) {
      for (const CloudRecord& r : block) {
        const double gx = inChunk(r.position, 0), gy = inChunk(r.position, 1);
        for (std::uint64_t i = partAt(gx - margin, 0); i <= partAt(gx + margin, 0); ++i)
          for (std::uint64_t j = partAt(gy - margin, 1); j <= partAt(gy + margin, 1); ++j) {
            const std::uint64_t part = i * cuts[1] + j;
            if (part < first || part >= last || !near(gx, 0, i) || !near(gy, 1, j)) continue;
            LODFORGE_TRY(writers[part - first].add(r));
          }
      }
      return Status{};
    }));
    for (RecordWriter& writer : writers) LODFORGE_TRY(writer.finish());
  }
  for (std::uint64_t part = 0; part < total; ++part) {
    const std::uint64_t i = part / cuts[1], j = part % cuts[1];
    Result<std::vector<CloudRecord>> records = readRecords(recordsPath(part));
    if (!records) return records.status();
    std::remove(recordsPath(part).c_str());
    Result<OwnedNormalFile> written = writeOwnedNormals(
        *records, options.normals,
        [&](const Vec3d& p) {
          return layout.owner(p) == chunk && partAt(inChunk(p, 0), 0) == i &&
                 partAt(inChunk(p, 1), 1) == j;
        },
        fmt::format("{}-{}-{}", partPath, i, j));
    if (!written) return written.status();
    files.push_back(std::move(*written));
    LODFORGE_TRY(checkCancelled());
  }
  return {};
}

}  // namespace

Status runNormals(const ChunkLayout& layout, const ChunkRuns& runs, std::size_t r,
                  std::uint64_t budget, const ReconstructOptions& options,
                  const std::string& directory, std::vector<OwnedNormalFile>& files) {
  const std::string runFile = runPath(directory, r);
  if (isDenseRun(runs, r, budget)) {
    LODFORGE_TRY(denseChunkNormals(runFile, layout, runs.chunks[runs.firstChunk[r]],
                                   runs.points[runs.firstChunk[r]], budget, options,
                                   normalsPath(directory, r), files));
  } else {
    Result<std::vector<CloudRecord>> records = readRecords(runFile);
    if (!records) return records.status();
    Result<OwnedNormalFile> written = writeOwnedNormals(
        *records, options.normals, [&](const Vec3d& p) { return runs.runOf(layout.owner(p)) == r; },
        normalsPath(directory, r));
    if (!written) return written.status();
    files.push_back(std::move(*written));
  }
  std::remove(runFile.c_str());
  return checkCancelled();
}

Result<std::vector<OwnedNormalFile>> runNormalFiles(const ChunkLayout& layout,
                                                    const ChunkRuns& runs, std::size_t r,
                                                    std::uint64_t budget,
                                                    const std::string& directory) {
  std::vector<std::string> paths;
  if (isDenseRun(runs, r, budget)) {
    const std::array<std::uint64_t, 2> cuts =
        denseCuts(layout, runs.points[runs.firstChunk[r]], budget);
    for (std::uint64_t i = 0; i < cuts[0]; ++i)
      for (std::uint64_t j = 0; j < cuts[1]; ++j)
        paths.push_back(fmt::format("{}-{}-{}", normalsPath(directory, r), i, j));
  } else {
    paths.push_back(normalsPath(directory, r));
  }
  std::vector<OwnedNormalFile> files;
  for (std::string& path : paths) {
    Result<std::uint64_t> bytes = fileSize(path);
    if (!bytes) return bytes.status();
    files.push_back({std::move(path), *bytes / sizeof(OwnedNormal)});
  }
  return files;
}

nlohmann::json reconstructIdentity(const std::string& input, const ReconstructOptions& options) {
  std::error_code error, unknown;
  const auto modified = std::filesystem::last_write_time(input, unknown);
  const Vec3d& view = options.normals.viewpoint;
  const Result<std::uint64_t> bytes = fileSize(input);
  return {
      {"input", std::filesystem::absolute(input, error).string()},
      {"bytes", bytes ? *bytes : 0},
      {"modified", unknown ? 0 : static_cast<std::int64_t>(modified.time_since_epoch().count())},
      {"voxel", options.voxel},
      {"chunkVoxels", options.chunkVoxels},
      {"chunkLength", options.chunkLength},
      {"radius", options.distance.radius},
      {"minPoints", options.distance.minPoints},
      {"decimateVoxels", options.decimateVoxels},
      {"edge", options.distance.edge},
      // How the distances are summed: runs kept by a version that summed otherwise are not ours.
      {"sums", "half-voxel point cells"},
      {"neighbours", options.normals.neighbours},
      {"orientation", static_cast<int>(options.normals.orientation)},
      {"viewpoint", {view.x, view.y, view.z}},
      {"salvage", options.salvageTruncated},
      {"placement", options.placement}};
}

Status forgetEarlierRuns(const std::string& workDirectory) {
  std::error_code ignored;
  std::filesystem::remove(reconstructStatePath(workDirectory), ignored);
  // run-R.pieces and their temporaries
  return removeFilesIn(workDirectory, [](const std::string& name) {
    return name.starts_with("run-") && name.find(".pieces") != std::string::npos;
  });
}

Result<Sorting> planSorting(const std::string& input, const std::string& workDirectory,
                            const ReconstructOptions& options) {
  Sorting sorting;
  sorting.cloudPath = workDirectory + "/cloud.points";
  Result<CloudSummary> cloud =
      copyCloud(input, sorting.cloudPath, options.salvageTruncated, options.transform);
  if (!cloud) return cloud.status();
  LODFORGE_TRY(checkSurfaceExtent(cloud->count, cloud->bounds, input));
  double spacing = 0;
  if (options.voxel <= 0) {
    Result<double> measured = medianSpacingOfFile(sorting.cloudPath, *cloud);
    if (!measured) return measured.status();
    spacing = *measured;
  }
  const double voxel = voxelFor(options, spacing, cloud->unitScale);
  if (options.voxel > 0)
    LODFORGE_TRY(checkVoxelFits(cloud->bounds, voxel, cloud->unitScale, input));
  Result<ChunkLayout> layout =
      layOutChunks(cloud->bounds, voxel, chunkVoxelsFor(options, voxel, cloud->unitScale),
                   options.distance.radius, input);
  if (!layout) return layout.status();
  LODFORGE_TRY(checkChunkFits(*layout, options, input));
  const double reach = options.distance.radius + 1;
  sorting.budget = runBudget(*layout, options);
  Result<ChunkRuns> runs = planRuns(sorting.cloudPath, *layout, reach, sorting.budget);
  if (!runs) return runs.status();
  sorting.cloud = std::move(*cloud);
  sorting.layout = *layout;
  sorting.runs = std::move(*runs);
  if (!sorting.cloud.hasNormals && options.normals.orientation == NormalOrientation::kPropagate) {
    LODFORGE_TRY(checkPropagationFits(sorting.cloud.count, options, input));
    LODFORGE_TRY(estimateNormalsWhole(sorting.cloudPath, sorting.cloud, options.normals));
  }
  sorting.normalsByRun =
      !sorting.cloud.hasNormals && options.normals.orientation != NormalOrientation::kPropagate;
  if (sorting.normalsByRun)
    LODFORGE_TRY(writeRuns(sorting.cloudPath, sorting.layout, reach, sorting.runs, workDirectory));
  return sorting;
}

ReconstructState stateOf(const Sorting& sorting) {
  const CloudSummary& cloud = sorting.cloud;
  return ReconstructState{sorting.layout,  sorting.runs,      sorting.budget,  cloud.count,
                          cloud.hasColors, !cloud.hasNormals, cloud.unitScale, cloud.warnings};
}

Result<ReconstructState> finishSorting(const Sorting& sorting, const std::string& workDirectory,
                                       const ReconstructOptions& options) {
  LODFORGE_TRY(writeRuns(sorting.cloudPath, sorting.layout, options.distance.radius + 1,
                         sorting.runs, workDirectory));
  std::error_code error;
  std::filesystem::remove(sorting.cloudPath, error);
  return stateOf(sorting);
}

namespace {

// Up or towards a viewpoint: each point's normal from its neighbours in the run that owns it
// (the run of the chunk it lies in), so a normal is computed once; then merged into the record
// file in id order.
Status estimateNormalsByRun(const Sorting& sorting, const ReconstructOptions& options,
                            const std::string& directory) {
  const ChunkLayout& layout = sorting.layout;
  const ChunkRuns& runs = sorting.runs;
  std::vector<OwnedNormalFile> files;
  Progress progress("reconstruct: normals", runs.runCount());
  for (std::size_t r = 0; r < runs.runCount(); ++r) {
    LODFORGE_TRY(runNormals(layout, runs, r, sorting.budget, options, directory, files));
    progress.advance(1);
  }
  progress.finish();
  return mergeNormals(sorting.cloudPath, files);
}

}  // namespace

Result<ReconstructState> sortIntoRuns(const std::string& input, const std::string& workDirectory,
                                      const ReconstructOptions& options) {
  Result<Sorting> sorting = planSorting(input, workDirectory, options);
  if (!sorting) return sorting.status();
  if (sorting->normalsByRun) LODFORGE_TRY(estimateNormalsByRun(*sorting, options, workDirectory));
  return finishSorting(*sorting, workDirectory, options);
}

Status makeRun(const ReconstructState& state, std::size_t r, const std::string& workDirectory,
               const ReconstructOptions& options, PieceSink& sink, Progress& progress,
               ReconstructStats& stats) {
  const ChunkRuns& runs = state.runs;
  const std::span<const std::uint64_t> chunks(runs.chunks.data() + runs.firstChunk[r],
                                              runs.firstChunk[r + 1] - runs.firstChunk[r]);
  if (isDenseRun(runs, r, runBudget(state.layout, options))) {
    stats.streamedChunks += 1;
    return streamDenseChunk(state.layout, chunks.front(), runPath(workDirectory, r), options,
                            state.hasColors, sink, progress);
  }
  Result<std::vector<CloudRecord>> records = readRecords(runPath(workDirectory, r));
  if (!records) return records.status();
  return makeChunks(state.layout, *records, chunks, options, state.hasColors, sink, progress,
                    nullptr);
}

std::optional<ReconstructState> resumedState(const std::string& input,
                                             const std::string& workDirectory,
                                             const ReconstructOptions& options) {
  if (!options.resume || !options.resumable) return std::nullopt;
  return loadReconstructState(reconstructStatePath(workDirectory),
                              reconstructIdentity(input, options));
}

Result<ReconstructState> stateOfRuns(const std::string& input, const std::string& workDirectory,
                                     const ReconstructOptions& options) {
  if (std::optional<ReconstructState> kept = resumedState(input, workDirectory, options))
    return std::move(*kept);
  LODFORGE_TRY(forgetEarlierRuns(workDirectory));
  Result<ReconstructState> sorted = sortIntoRuns(input, workDirectory, options);
  if (!sorted) return sorted.status();
  if (options.resumable)
    LODFORGE_TRY(saveReconstructState(reconstructStatePath(workDirectory),
                                      reconstructIdentity(input, options), *sorted));
  return sorted;
}

ReconstructStats statsOf(const ReconstructState& state) {
  ReconstructStats stats;
  stats.grid = state.layout.grid;
  stats.unitScale = state.unitScale;
  stats.chunkVoxels = state.layout.n;
  stats.points = state.points;
  stats.chunks = state.layout.chunkCount();
  stats.runs = state.runs.runCount();
  stats.hasColors = state.hasColors;
  stats.estimatedNormals = state.estimatedNormals;
  stats.warnings = state.warnings;
  return stats;
}

}  // namespace lodforge
