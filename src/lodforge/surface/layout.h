// The reconstruction's meta grid (large-meshes paper §3.1): one voxel lattice over the cloud,
// cut into chunks of N voxels along an edge, numbered x fastest. A point belongs to every chunk
// holding a lattice corner within the distance radius of it (the chunk's overlap), so each chunk
// sees every point its corners' values depend on.
#pragma once

#include <array>
#include <cassert>
#include <cstdint>
#include <string>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/surface/grid.h"

namespace lodforge {

struct ChunkBox {
  std::array<std::uint64_t, 3> lo{}, hi{};  // inclusive chunk coordinates
};

struct ChunkLayout {
  VoxelGrid grid;
  std::uint32_t n = 64;  // voxels along a chunk's edge
  std::array<std::uint64_t, 3> chunks{};

  std::uint64_t chunkCount() const { return chunks[0] * chunks[1] * chunks[2]; }
  std::uint64_t chunkIndex(std::uint64_t x, std::uint64_t y, std::uint64_t z) const {
    assert(x < chunks[0] && y < chunks[1] && z < chunks[2]);
    return (z * chunks[1] + y) * chunks[0] + x;
  }
  std::array<std::uint64_t, 3> chunkAt(std::uint64_t c) const {
    assert(c < chunkCount());
    return {c % chunks[0], (c / chunks[0]) % chunks[1], c / (chunks[0] * chunks[1])};
  }
  // The chunks holding a corner within `radius` voxels of p's point cell (pointCellOf): every
  // point of a cell reaches the same chunks, so each chunk sums a cell's points alike.
  ChunkBox reach(const Vec3d& p, double radius) const;
  // The chunk whose cells hold p.
  std::uint64_t owner(const Vec3d& p) const;
  // Whether the vertex on lattice edge `key` (edgeKey) lies in a chunk face, i.e. in a plane of
  // corners a multiple of N along an axis it does not run along: only those are in two chunks.
  bool onChunkFace(std::uint64_t key) const;
  // Per axis, the chunk plane (corners k·N along it) a vertex on lattice edge `key` lies in, or
  // -1 where it lies in none.
  std::array<std::int64_t, 3> chunkPlanesOf(std::uint64_t key) const;
  // The last chunk (in chunk order) that holds lattice edge `key`: after it, nobody asks again.
  std::uint64_t lastChunkHolding(std::uint64_t key) const;
};

// The lattice and its chunks over `bounds` at `voxel` (a margin of radius + 1 voxels round the
// points). Refuses a lattice too fine to name its edges in 64 bits.
Result<ChunkLayout> layOutChunks(const Aabbd& bounds, double voxel, std::uint32_t chunkVoxels,
                                 double radius, const std::string& name);

// Bad input for a surface: fewer than 4 points, or all on a line or at one position.
Status checkSurfaceExtent(std::uint64_t points, const Aabbd& bounds, const std::string& name);
// A voxel the user gave must fit a quarter of the cloud's longest side (a larger one makes a
// handful of triangles far bigger than the cloud); a usage error says the size and a voxel that
// works, in the cloud's units (`unitScale`: the frame's length of one, CloudSummary).
Status checkVoxelFits(const Aabbd& bounds, double voxel, double unitScale, const std::string& name);

}  // namespace lodforge
