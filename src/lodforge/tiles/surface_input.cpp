#include "lodforge/tiles/surface_input.h"

#include <algorithm>
#include <filesystem>
#include <limits>

#include <fmt/format.h>

#include "lodforge/core/cluster.h"
#include "lodforge/core/directory.h"
#include "lodforge/surface/layout.h"
#include "lodforge/surface/resume_state.h"

namespace lodforge {

namespace {

// Pieces into leaf chunks: one reconstruction chunk, one leaf cell.
class LeafChunkSink : public PieceSink {
 public:
  LeafChunkSink(const ChunkInputOptions& options, std::uint64_t minTriangles)
      : options_(options), minTriangles_(minTriangles) {}

  Status begin(const ChunkLayout& layout, bool colors) override {
    layout_ = layout;
    colors_ = colors;
    ChunkGrid grid;
    grid.origin = layout.grid.origin;
    grid.size = layout.grid.voxel * layout.n;
    for (std::size_t a = 0; a < 3; ++a) {
      if (layout.chunks[a] > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max()))
        return Error{ErrorKind::kUsage,
                     "the surface has too many chunks along an axis for "
                     "the tiles' grid: use a larger --voxel or --chunk-size"};
      grid.dims[a] = static_cast<std::int32_t>(layout.chunks[a]);
    }
    chunks_ = std::make_unique<ChunkWriter>(grid, options_.workDirectory + "/chunks",
                                            options_.chunkBufferBytes, options_.keepInMemory);
    return {};
  }

  Status add(std::uint64_t chunk, const SurfacePiece& piece) override {
    if (piece.indices.empty()) return {};
    const std::vector<char> kept = keptTriangles(layout_, piece, minTriangles_, dropped_);
    const std::array<std::uint64_t, 3> at = layout_.chunkAt(chunk);
    const ChunkCell cell{static_cast<std::int32_t>(at[0]), static_cast<std::int32_t>(at[1]),
                         static_cast<std::int32_t>(at[2])};
    corners_.resize(piece.positions.size());
    for (std::size_t v = 0; v < piece.positions.size(); ++v) corners_[v] = leafCorner(piece, v);
    for (std::size_t t = 0; t < kept.size(); ++t) {
      if (!kept[t]) continue;
      const std::array<CutCorner, 3> triangle{corners_[piece.indices[3 * t]],
                                              corners_[piece.indices[3 * t + 1]],
                                              corners_[piece.indices[3 * t + 2]]};
      LODFORGE_TRY(chunks_->add(cell, triangle));
      ++triangles_;
      bounds_.add(triangle[0].position);
      bounds_.add(triangle[1].position);
      bounds_.add(triangle[2].position);
    }
    return {};
  }

  std::unique_ptr<ChunkWriter> take() { return std::move(chunks_); }
  std::uint64_t triangles() const { return triangles_; }
  std::uint64_t droppedPieces() const { return dropped_; }
  const Aabbd& bounds() const { return bounds_; }
  bool colors() const { return colors_; }

 private:
  // The vertex as the tiler takes it: on a chunk face, the face's plane coordinate bit for bit
  // (k·N voxels from the lattice's origin and k chunk edges from the grid's may round apart).
  // The piece's vertex number names it within the chunk, where it is stored once.
  CutCorner leafCorner(const SurfacePiece& piece, std::size_t v) const {
    CutCorner corner;
    corner.position = piece.positions[v];
    const std::array<std::int64_t, 3> planes = layout_.chunkPlanesOf(piece.edges[v]);
    for (int a = 0; a < 3; ++a)
      if (planes[static_cast<std::size_t>(a)] >= 0)
        corner.position[a] = chunks_->grid().plane(
            a, static_cast<std::int32_t>(planes[static_cast<std::size_t>(a)]));
    corner.normal = piece.normals[v];
    corner.color = piece.colors.empty() ? Rgba8{255, 255, 255, 255} : piece.colors[v];
    corner.source = v;
    return corner;
  }

  const ChunkInputOptions& options_;
  std::uint64_t minTriangles_;
  ChunkLayout layout_;
  bool colors_ = false;
  std::unique_ptr<ChunkWriter> chunks_;
  std::vector<CutCorner> corners_;
  std::uint64_t triangles_ = 0, dropped_ = 0;
  Aabbd bounds_;
};

}  // namespace

std::string surfaceWorkDirectory(const std::string& tilesWorkDirectory) {
  return tilesWorkDirectory + "/surface";
}

bool surfaceWorkKept(const std::string& tilesWorkDirectory) {
  std::error_code ignored;
  return std::filesystem::exists(reconstructStatePath(surfaceWorkDirectory(tilesWorkDirectory)),
                                 ignored);
}

Result<ChunkInput> surfaceChunkInput(const std::string& path, const ChunkInputOptions& options,
                                     ReconstructOptions reconstruct, ReconstructStats& stats) {
  reconstruct.transform = options.transform;
  reconstruct.salvageTruncated = options.salvageTruncated;
  // The chunk store's buffer is held beside the reconstruction.
  if (reconstruct.memoryLimit > 0)
    reconstruct.memoryLimit -= std::min(reconstruct.memoryLimit / 2, options.chunkBufferBytes);
  // In a job, rank 0's: the directory it removes when done.
  const bool lead = !reconstruct.acrossRanks || clusterRank() == 0;
  const std::string workPath = surfaceWorkDirectory(options.workDirectory);
  ScopedDirectory work(lead ? workPath : std::string());
  std::error_code error;
  if (lead) std::filesystem::create_directories(workPath, error);
  Status created =
      error ? Status(ioError(workPath, fmt::format("cannot create: {}", error.message())))
            : Status();
  // (In a job the others wait in the reconstruction's steps: rank 0's failure is agreed first.)
  if (reconstruct.acrossRanks) created = agreeAcrossRanks(created);
  LODFORGE_TRY(created);
  LeafChunkSink sink(options, reconstruct.minTriangles);
  Result<ReconstructStats> made = reconstructPieces(path, workPath, reconstruct, sink);
  if (!made) {
    // (A job saves its state for the ranks whether or not it can be resumed.)
    if (reconstruct.resumable && surfaceWorkKept(options.workDirectory)) work.path.clear();
    return made.status();
  }
  stats = *made;
  if (!lead) return ChunkInput{};
  stats.triangles = sink.triangles();
  stats.droppedPieces = sink.droppedPieces();
  if (sink.triangles() == 0) return noSurface(path, stats.grid.voxel / stats.unitScale);
  ChunkInput input;
  input.chunks = sink.take();
  LODFORGE_TRY(input.chunks->flush());
  input.inputTriangles = sink.triangles();
  input.bounds = sink.bounds();
  input.colors = sink.colors();
  input.warnings = stats.warnings;
  input.streamed = true;
  return input;
}

}  // namespace lodforge
