// One chunk's piece of the surface (large-meshes paper §3.1): the signed distance at its corners
// and a corner of margin, polygonized within its own corners, a vertex's colour its nearest
// point's. A chunk is made from its points held in memory (a run of chunks read whole) or, when
// its points alone are more than a run may hold, streamed from its run file in blocks: the sums
// then live in the point cells and at the corners only, and memory does not grow with the
// points. Both sum a cell's points in input order and pick the same nearest point, so they make
// the same bits.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/surface/cloud_file.h"
#include "lodforge/surface/implicit.h"
#include "lodforge/surface/layout.h"
#include "lodforge/surface/marching_tetrahedra.h"

namespace lodforge {

// The chunk's piece from its members: indices into `records` (ascending, so in input order) of
// every record within the radius and a voxel of the chunk.
SurfacePiece heldChunkPiece(const ChunkLayout& layout, std::uint64_t chunk,
                            std::span<const std::uint32_t> members,
                            std::span<const CloudRecord> records, const DistanceOptions& distance,
                            bool colors);

// The chunk's piece from `runFile`, which holds its members in input order (and nothing else
// that reaches its corners), read twice in blocks (distances, then colours).
Result<SurfacePiece> streamedChunkPiece(const ChunkLayout& layout, std::uint64_t chunk,
                                        const std::string& runFile, const DistanceOptions& distance,
                                        bool colors);

}  // namespace lodforge
