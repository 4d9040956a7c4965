// `tiles --surface`: the large-meshes paper's "Chunk" path (§3.1, Table 2). The cloud is
// reconstructed chunk by chunk straight into the tiler's chunk grid: each reconstruction chunk
// is one leaf chunk, with no global mesh and no re-segmentation. The leaf grid is the
// reconstruction's meta grid, and a vertex on a chunk face gets the leaf grid's plane coordinate
// exactly, so the octree finds it on its leaves' outer faces and keeps it locked (§3.3).
#pragma once

#include <string>

#include "lodforge/core/status.h"
#include "lodforge/surface/reconstruct.h"
#include "lodforge/tiling/chunk_input.h"

namespace lodforge {

// Where the reconstruction keeps its work in the tiles' work directory: kept when it is
// interrupted after the points are sorted, for --resume (reconstruct.resume).
std::string surfaceWorkDirectory(const std::string& tilesWorkDirectory);
// Whether that holds an interrupted reconstruction's work.
bool surfaceWorkKept(const std::string& tilesWorkDirectory);

// The chunks of `path`'s surface (work files under options.workDirectory). options.transform
// places the points; options.chunkBufferBytes and keepInMemory are the chunk store's.
// `stats` receives the reconstruction's figures. No surface at all is bad input. With
// reconstruct.acrossRanks every rank of the job calls it; rank 0 gets the chunks, the others an
// empty ChunkInput (they take rank 0's chunks after).
Result<ChunkInput> surfaceChunkInput(const std::string& path, const ChunkInputOptions& options,
                                     ReconstructOptions reconstruct, ReconstructStats& stats);

}  // namespace lodforge
