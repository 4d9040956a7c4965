#include "lodforge/surface/reconstruct.h"

#include <algorithm>
#include <cassert>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "lodforge/core/cluster.h"
#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/output_claim.h"
#include "lodforge/core/progress.h"
#include "lodforge/surface/cloud_file.h"
#include "lodforge/surface/layout.h"
#include "lodforge/surface/mesh_join.h"
#include "lodforge/surface/point_index.h"
#include "lodforge/surface/reconstruct_ranks.h"
#include "lodforge/surface/reconstruct_steps.h"
#include "lodforge/surface/resume_state.h"

namespace lodforge {

namespace {

// Every run in chunk order: a run whose pieces an earlier reconstruction kept is replayed, the
// others are made (and their pieces kept when the reconstruction can be resumed).
Status makeRuns(const ReconstructState& state, const std::string& workDirectory,
                const ReconstructOptions& options, PieceSink& sink, ReconstructStats& stats) {
  Progress progress("reconstruct: chunks", state.runs.chunks.size());
  std::error_code error;
  for (std::size_t r = 0; r < state.runs.runCount(); ++r) {
    const std::string kept = piecesPath(workDirectory, r);
    if (options.resume && std::filesystem::exists(kept, error)) {
      LODFORGE_TRY(replayPieces(kept, sink));
      stats.resumedRuns += 1;
      progress.advance(state.runs.firstChunk[r + 1] - state.runs.firstChunk[r]);
      continue;
    }
    std::optional<PieceWriter> writer;
    if (options.resumable) {
      Result<PieceWriter> created = PieceWriter::create(kept);
      if (!created) return created.status();
      writer.emplace(std::move(*created));
    }
    KeptPieces tee(&sink, writer ? &*writer : nullptr);
    LODFORGE_TRY(makeRun(state, r, workDirectory, options, tee, progress, stats));
    if (writer) {
      LODFORGE_TRY(writer->finish());
      checkpointReached("run");
    }
    std::filesystem::remove(runPath(workDirectory, r), error);
  }
  progress.finish();
  return {};
}

}  // namespace

Result<ReconstructStats> reconstructPieces(const std::string& input,
                                           const std::string& workDirectory,
                                           const ReconstructOptions& options, PieceSink& sink) {
  if (options.acrossRanks) return reconstructAcrossRanks(input, workDirectory, options, sink);
  Result<ReconstructState> state = stateOfRuns(input, workDirectory, options);
  if (!state) return state.status();
  ReconstructStats stats = statsOf(*state);
  LODFORGE_TRY(sink.begin(state->layout, state->hasColors));
  LODFORGE_TRY(makeRuns(*state, workDirectory, options, sink, stats));
  return stats;
}

Status noSurface(const std::string& input, double voxel) {
  return badInput(input, fmt::format("no surface at voxel {:g}: the points are too sparse for it "
                                     "(try a larger --voxel or --radius, or a smaller "
                                     "--min-points)",
                                     voxel));
}

std::string reconstructWorkDirectory(const std::string& output) {
  return output + ".work";
}

namespace {

// What reconstructToFile writes with (rank 0's in a job): its work directory, claimed, locked
// (resumable: a stable name) and created, and the mesh's work files in it.
struct MeshWork {
  WorkLock lock;
  ScopedDirectory work;  // removed before the lock goes
  std::unique_ptr<PlyMeshOutput> mesh;
};

Status prepareMeshWork(const std::string& output, const ReconstructOptions& options,
                       MeshWork& out) {
  const std::string path =
      options.resumable ? reconstructWorkDirectory(output) : temporaryPathFor(output + ".work");
  if (options.resumable) {
    LODFORGE_TRY(claimWorkDirectory(path));
    Result<WorkLock> locked = lockWorkDirectory(path);
    if (!locked) return locked.status();
    out.lock = std::move(*locked);
  }
  out.work.path = path;  // ours now: another run's would have held the lock
  std::error_code error;
  std::filesystem::create_directories(path, error);
  if (error) return ioError(path, fmt::format("cannot create: {}", error.message()));
  Result<std::unique_ptr<PlyMeshOutput>> mesh = PlyMeshOutput::create(path);
  if (!mesh) return mesh.status();
  out.mesh = std::move(*mesh);
  return {};
}

// The other ranks' sink in a job: their pieces go to the runs' files.
class NoPieces : public PieceSink {
 public:
  Status begin(const ChunkLayout&, bool) override { return {}; }
  Status add(std::uint64_t, const SurfacePiece&) override { return {}; }
};

}  // namespace

Result<ReconstructStats> reconstructToFile(const std::string& input, const std::string& output,
                                           const ReconstructOptions& options) {
  assert(!options.acrossRanks || options.resumable);  // the ranks share one work directory
  const bool lead = !options.acrossRanks || clusterRank() == 0;
  MeshWork made;
  const Status prepared = lead ? prepareMeshWork(output, options, made) : Status{};
  LODFORGE_TRY(options.acrossRanks ? agreeAcrossRanks(prepared) : prepared);
  const std::string workPath = lead ? made.work.path : reconstructWorkDirectory(output);
  if (options.acrossRanks) setActivityDirectory(workPath + "/ranks");
  std::optional<PieceJoiner> joiner;
  NoPieces none;
  if (made.mesh) joiner.emplace(options.minTriangles, *made.mesh);
  Result<ReconstructStats> stats =
      reconstructPieces(input, workPath, options, joiner ? static_cast<PieceSink&>(*joiner) : none);
  Status finished = stats.status();
  if (stats && joiner) {
    stats->vertices = joiner->vertices();
    stats->triangles = joiner->triangles();
    stats->droppedPieces = joiner->droppedPieces();
    finished = stats->triangles == 0
                   ? noSurface(input, stats->grid.voxel)
                   : made.mesh->finish(output, stats->hasColors, "lodforge reconstruct");
  }
  if (options.acrossRanks) finished = agreeAcrossRanks(finished);
  if (finished.ok()) return stats;
  // Stopped or failed once the points were sorted (the last pass included): the work stays for
  // --resume, unless the input itself makes no surface.
  std::error_code error;
  if (finished.error().kind != ErrorKind::kBadInput &&
      std::filesystem::exists(reconstructStatePath(workPath), error))
    made.work.path.clear();
  return finished.error();
}

Result<ReconstructedMesh> reconstructPoints(std::vector<Vec3d> positions,
                                            std::vector<Vec3f> normals, std::vector<Rgba8> colors,
                                            const std::string& name,
                                            const ReconstructOptions& options,
                                            std::vector<SurfacePiece>* pieces) {
  assert(normals.empty() || normals.size() == positions.size());
  assert(colors.empty() || colors.size() == positions.size());
  Aabbd bounds;
  for (const Vec3d& p : positions) bounds.add(p);
  LODFORGE_TRY(checkSurfaceExtent(positions.size(), bounds, name));
  std::optional<PointIndex> index;
  if (options.voxel <= 0 || normals.empty()) index.emplace(positions);
  const double spacing = options.voxel > 0 ? 0 : medianSpacing(positions, *index);
  const double voxel = voxelFor(options, spacing, 1);
  if (options.voxel > 0) LODFORGE_TRY(checkVoxelFits(bounds, voxel, 1, name));
  Result<ChunkLayout> layout =
      layOutChunks(bounds, voxel, chunkVoxelsFor(options, voxel, 1), options.distance.radius, name);
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
