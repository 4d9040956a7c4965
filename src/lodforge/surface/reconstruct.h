// `lodforge reconstruct`: a surface from a point cloud, chunk by chunk (large-meshes paper §3.1):
// a meta grid of chunks of N voxels along an edge over one global lattice (surface/layout); each
// chunk takes the points within the distance radius of its corners (its overlap), computes the
// signed distance at its corners (surface/implicit) and polygonizes its cells
// (surface/marching_tetrahedra). Chunks that share a face compute its corners' values and
// vertices bit for bit alike, so the pieces join by vertex name into one mesh without a crack
// (§3.3's unification, by construction; surface/mesh_join).
//
// Out of core (reconstructToFile): the cloud is copied into a record file, chunks are worked in
// runs that fit the memory budget (surface/chunk_runs), and the joined mesh streams to work
// files made one PLY at the end: memory holds one run, the chunks in flight and a wavefront of
// chunk-face vertices, whatever the cloud's size. Deterministic for any thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/surface/implicit.h"
#include "lodforge/surface/marching_tetrahedra.h"
#include "lodforge/surface/mesh_join.h"
#include "lodforge/surface/normals.h"

namespace lodforge {

struct ReconstructOptions {
  // Lengths in the cloud's own units (feet for a CRS in feet), also when `transform` places the
  // points in a local frame in metres: they are scaled with the points.
  double voxel = 0;                // 0: twice the median spacing of the points
  std::uint32_t chunkVoxels = 64;  // N: voxels along a chunk's edge
  double chunkLength = 0;          // when > 0, N is this over the voxel (at least 4)
  DistanceOptions distance;        // radius in voxels, fewest points near a corner
  NormalOptions normals;           // for points without normals
  std::uint64_t memoryLimit = 0;   // bytes, 0: the default budget (kDefaultRunPoints a run)
  std::uint64_t runPoints = 0;     // points a run of chunks holds; 0: from the memory limit
  std::uint64_t minTriangles = 0;  // connected pieces with fewer triangles are dropped
  // Each chunk's piece thinned by edge collapses within this many voxels (piece_decimation.h);
  // 0: the marching tetrahedra's triangles as they are.
  double decimateVoxels = 0;
  bool salvageTruncated = false;
  // Keep in the work directory what lets an interrupted reconstruction go on (resume_state.h):
  // the state after the points are sorted into runs, and each finished run's pieces.
  bool resumable = false;
  // Go on from such work when it was made from the same input and options.
  bool resume = false;
  // Names what `transform` does (a CRS), for the resume identity.
  std::string placement;
  // Every rank of an MPI job (core/cluster) calls with the same input, work directory and options,
  // and they share the runs (docs/distributed.md, surface/reconstruct_ranks.h): rank 0 sorts the
  // points into runs and saves the state, the ranks estimating missing normals run by run; the
  // ranks make the runs, each taken by the first rank free, into their pieces files; rank 0
  // replays every run's pieces in chunk order into its sink, which so sees what one process
  // would give it (the other ranks' sinks see nothing). Each step's outcome is agreed between
  // the ranks. With a memory limit the runs' size follows rank 0's threads (the grids in
  // flight), so one process writes the same bytes when it has as many threads as rank 0.
  bool acrossRanks = false;
  // Applied to every input point before anything else (a CRS to a local frame, in metres);
  // false: the point cannot be placed, which is bad input. Given normals turn with it.
  std::function<bool(Vec3d, Vec3d&)> transform;
};

// Points a run holds when no memory limit says otherwise (≈ 30 MB with its chunks).
constexpr std::uint64_t kDefaultRunPoints = 200'000;

struct ReconstructStats {
  VoxelGrid grid;        // in the frame the points were placed in (local metres with a transform)
  double unitScale = 1;  // that frame's length of one of the cloud's units (CloudSummary)
  std::uint32_t chunkVoxels = 0;
  std::uint64_t points = 0, chunks = 0, runs = 0, vertices = 0, triangles = 0;
  std::uint64_t droppedPieces = 0;
  std::uint64_t streamedChunks = 0;  // chunks denser than a run, streamed from their run file
  std::uint64_t resumedRuns = 0;     // runs whose pieces an interrupted reconstruction kept
  bool estimatedNormals = false;
  bool hasColors = false;  // the points had colours, and so do the vertices
  // A job's (acrossRanks): the chunks each rank made, and the seconds from the start at which
  // rank 0 had sorted the points, the ranks had made their runs and rank 0 had joined them.
  std::vector<std::uint64_t> rankChunks;
  std::vector<double> rankMadeSeconds;  // when each rank was done with its runs
  double sortedSeconds = 0, madeSeconds = 0, joinedSeconds = 0;
  std::vector<std::string> rankStages;  // rank 0's: what each rank read and wrote by stage
  std::vector<std::string> warnings;    // the input's reading (CloudSummary::warnings)
};

// The mesh in memory (tests, small clouds): pieces joined by vertex name.
struct ReconstructedMesh : ReconstructStats {
  std::vector<Vec3d> positions;
  std::vector<Vec3f> normals;  // the distance's gradient at each vertex
  std::vector<Rgba8> colors;   // empty when the points have none
  std::vector<std::uint32_t> indices;
};

// Reads `input` (any point format) and hands every chunk's piece to `sink` in chunk order, out
// of core, with its work files in `workDirectory` (which must exist; they are removed as they
// are used). Fills the layout's figures; the sink counts what it keeps. With
// options.acrossRanks, every rank calls it (rank 0's sink gets the pieces).
Result<ReconstructStats> reconstructPieces(const std::string& input,
                                           const std::string& workDirectory,
                                           const ReconstructOptions& options, PieceSink& sink);

// Bad input: no surface came out of `input` at `voxel`, and what might make one.
Status noSurface(const std::string& input, double voxel);

// Where a resumable reconstructToFile keeps its work: beside the output, a stable name.
std::string reconstructWorkDirectory(const std::string& output);

// Reads `input` (any point format) and writes the surface to `output` as binary PLY, out of
// core: the pieces joined by vertex name. No surface at all is bad input (nothing written).
// With options.resumable, an interruption after the points are sorted keeps the work directory
// (reconstructWorkDirectory) for options.resume; it is locked while in use, so a second run on
// the same output is refused. With options.acrossRanks (which needs options.resumable: the ranks
// share that directory), every rank calls it and rank 0 writes the mesh.
Result<ReconstructStats> reconstructToFile(const std::string& input, const std::string& output,
                                           const ReconstructOptions& options);

// The same from points in memory, as one run (normals may be empty: estimated then). `pieces`,
// when given, receives every chunk's piece as made.
Result<ReconstructedMesh> reconstructPoints(std::vector<Vec3d> positions,
                                            std::vector<Vec3f> normals, std::vector<Rgba8> colors,
                                            const std::string& name,
                                            const ReconstructOptions& options,
                                            std::vector<SurfacePiece>* pieces = nullptr);

}  // namespace lodforge
