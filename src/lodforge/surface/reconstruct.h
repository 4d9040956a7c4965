// `lodforge reconstruct`: a surface from a point cloud, chunk by chunk (large-meshes paper §3.1):
// a meta grid of chunks of N voxels along an edge over one global lattice; each chunk takes the
// points within the distance radius of its corners (its overlap), computes the signed distance
// at its corners (surface/implicit) and polygonizes its cells (surface/marching_tetrahedra).
// Chunks that share a face compute its corners' values and vertices bit for bit alike, so the
// pieces join by vertex name into one mesh without a crack (§3.3's unification, by
// construction). Deterministic for any thread count.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/surface/implicit.h"
#include "lodforge/surface/marching_tetrahedra.h"
#include "lodforge/surface/normals.h"

namespace lodforge {

struct ReconstructOptions {
  double voxel = 0;                // metres; 0: twice the median spacing of the points
  std::uint32_t chunkVoxels = 64;  // N: voxels along a chunk's edge
  DistanceOptions distance;        // radius in voxels, fewest points near a corner
  NormalOptions normals;           // for points without normals
  std::uint64_t memoryLimit = 0;   // bytes, 0: unlimited
  std::uint64_t minTriangles = 0;  // connected pieces with fewer triangles are dropped
  bool salvageTruncated = false;
};

// The mesh as chunks made it: pieces joined by vertex name.
struct ReconstructedMesh {
  VoxelGrid grid;
  std::uint32_t chunkVoxels = 0;
  std::vector<Vec3d> positions;
  std::vector<Rgba8> colors;  // empty when the points have none
  std::vector<std::uint32_t> indices;
  std::uint64_t points = 0, chunks = 0, droppedPieces = 0;
  bool estimatedNormals = false;
};

// Reads `input` (any point format) and reconstructs it in memory-bounded chunks.
Result<ReconstructedMesh> reconstructSurface(const std::string& input,
                                             const ReconstructOptions& options);

// The same from points in memory (normals may be empty: estimated then).
Result<ReconstructedMesh> reconstructPoints(std::vector<Vec3d> positions,
                                            std::vector<Vec3f> normals, std::vector<Rgba8> colors,
                                            const std::string& name,
                                            const ReconstructOptions& options,
                                            std::vector<SurfacePiece>* pieces = nullptr);

// Writes the mesh as binary PLY (double positions when far from the origin; vertex normals from
// the triangles; colours when it has them), under a temporary name renamed when complete.
Status writeReconstruction(const ReconstructedMesh& mesh, const std::string& path);

}  // namespace lodforge
