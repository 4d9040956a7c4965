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

}  // namespace lodforge
