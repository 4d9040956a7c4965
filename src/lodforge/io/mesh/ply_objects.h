// A PLY's faces with object ids (PlyHeader::hasObjectIds) as a Model's objects: one per distinct
// id, in ascending id order, named "object <id>".
#pragma once

#include <cstdint>
#include <vector>

#include "lodforge/core/model.h"

namespace lodforge {

// Groups triangles (3 global vertex indices each) by their object id; each object gets its own
// copy of the vertices it uses, in ascending file order, so objects are self-contained (shared
// vertices are duplicated). `normals` and `colors` are empty or one per position.
void splitPlyObjects(Model& model, const std::vector<Vec3f>& positions,
                     const std::vector<Vec3f>& normals, const std::vector<Rgba8>& colors,
                     const std::vector<std::uint32_t>& triangles,
                     const std::vector<std::uint32_t>& triangleObjects);

}  // namespace lodforge
