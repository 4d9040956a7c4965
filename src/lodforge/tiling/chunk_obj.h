// A Wavefront OBJ streamed into the chunk grid, never held in memory (large-meshes paper §3.3–3.4,
// as chunk_ply does for PLY): a first pass copies its positions (and vertex colours), texture
// coordinates and normals to work files, finds the bounds and counts the faces; its material
// libraries are read (Kd colours, map_Kd textures: obj_materials.h); where a face corner has no
// normal (or a CRS turns the positions) one more pass sums area-weighted face normals per
// vertex; the last pass reads the faces again, fetches their corners through block caches over
// the work files and cuts them into the chunk files. Lines are checked as they are read: a bad
// number or an index outside the file is refused naming its line.
#pragma once

#include <string>

#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_input.h"

namespace lodforge {

Result<ChunkInput> chunkObj(const std::string& path, const ChunkInputOptions& options);

}  // namespace lodforge
