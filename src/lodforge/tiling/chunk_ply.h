// A PLY streamed into the chunk grid, never held in memory (large-meshes paper §3.3–3.4): its
// vertices to a work file with the bounds, then, where the file has no normals or has object
// ids, one pass over the faces for normals and object extents, then the faces cut into the
// chunk files, their corners fetched through a block cache over the work file.
#pragma once

#include <string>

#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_input.h"

namespace lodforge {

Result<ChunkInput> chunkPly(const std::string& path, const ChunkInputOptions& options);

// In a job of several ranks (docs/distributed.md): the faces of a PLY that can be read in
// slices, one per rank (binary, faces found by their index, the normals in the file: a normals
// pass sums over the whole file; no object ids, texture coordinates, transform or salvage;
// chunks on disk), or 0: then rank 0 chunks it alone.
Result<std::uint64_t> plyFacesInSlices(const std::string& path, const ChunkInputOptions& options);

// Every rank reads its slice of the vertices (into the shared vertex file) and then of the
// faces (into chunk pieces of its own, chunkPieceDirectory); each gets the same input,
// its chunks the ranks' pieces. Collective: every rank calls it, and each step ends with every
// rank's outcome (faces that cannot be found by index: kUnsupported on every rank).
Result<ChunkInput> chunkPlyInSlices(const std::string& path, const ChunkInputOptions& options);

}  // namespace lodforge
