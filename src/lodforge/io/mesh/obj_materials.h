// An OBJ's textured materials (MTL `map_Kd`): each texture's file found (relative to the OBJ or
// its material library, Windows separators taken as folders, an absolute path that is not here
// looked for beside the file by its name), its header read, and the material, image and UV
// transform (`-o`, `-s`, `-clamp`) it becomes in the model. A texture that cannot be found or
// read is a warning naming it, and its material draws grey.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <tiny_obj_loader.h>

#include "lodforge/core/model.h"

namespace lodforge {

struct ObjTextures {
  // Per MTL material: its material in Model::materials when it has a usable texture,
  // kNoMaterial when it has none (its Kd goes to the vertex colours).
  std::vector<std::uint32_t> material;
  // Per MTL material: (scale u, scale v, offset u, offset v) of its map_Kd (-s, -o).
  std::vector<std::array<float, 4>> transform;

  bool textured(int mtl) const {
    return mtl >= 0 && static_cast<std::size_t>(mtl) < material.size() &&
           material[static_cast<std::size_t>(mtl)] != kNoMaterial;
  }
  // An OBJ texture coordinate (origin bottom left) as glTF's (top left), through the map's
  // transform.
  Vec2f toUv(int mtl, float u, float v) const;
};

// `searchDirectories` end with '/'. A material whose texture is missing gets a grey Kd.
ObjTextures resolveObjTextures(std::vector<tinyobj::material_t>& materials,
                               const std::vector<std::string>& searchDirectories, Model& model,
                               std::vector<std::string>* warnings);

}  // namespace lodforge
