// The interchange formats users meet beside ours (OFF, FBX, Collada, 3DS, IFC, X3D, 3MF, …),
// read through Debian's assimp. Each node's mesh becomes one object with its world transform
// applied, named by its node and placed at its path in the node tree; instances are expanded.
// Materials keep their name, colour, opacity (below 1: BLEND, double-sided), metallic,
// roughness, emissive and two-sidedness; the diffuse colour times any vertex colour becomes the
// vertex colour, as the glTF reader does. PLY, OBJ, STL and glTF keep our own readers.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

// Whether the extension is one assimp reads for us (lower case, without the dot).
bool isAssimpExtension(std::string_view extension);

// Base-colour textures (files beside it, or embedded) and their UVs too (assimp_textures.h);
// one that cannot be read is a warning.
Result<Model> readAssimp(const std::string& path, std::vector<std::string>* warnings = nullptr);
// The same from bytes in memory; `name` names them in errors and its extension picks the format
// (the fuzzer).
Result<Model> readAssimpFromMemory(std::span<const std::byte> bytes, const std::string& name);

}  // namespace lodforge
