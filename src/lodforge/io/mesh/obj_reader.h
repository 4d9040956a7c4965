// Wavefront OBJ reader (tinyobjloader, double precision). Every `o` or `g` starts an object;
// polygons are fan-triangulated; colours come from vertex colours (`v x y z r g b`) or the
// material's diffuse colour (Kd) when the .mtl is found beside the file. Only vertices that faces
// use are kept, unless the file has no faces: then it is one object of all its vertices.
// Textures (`map_Kd`) become textured materials with the faces' `vt` as UVs (obj_materials.h); a
// texture that cannot be read is a warning, and its material grey.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

Result<Model> readObj(const std::string& path, std::vector<std::string>* warnings = nullptr);
// From memory, for fuzzing and tests: material libraries are not loaded.
Result<Model> readObjFromMemory(std::span<const std::byte> bytes, const std::string& name);

}  // namespace lodforge
