// An assimp scene's base-colour textures (FBX, Collada, 3DS, …): each material's diffuse or
// base-colour texture, from a file beside the model (a path from another machine looked for by
// its name, with a warning) or embedded in the file (compressed bytes kept as they are; raw
// texels encoded as PNG), its wrap modes and the UV channel it reads. A texture that cannot be
// found or read is a warning naming it; its material then draws without it.
#pragma once

#include <string>
#include <vector>

#include <assimp/scene.h>

#include "lodforge/core/model.h"

namespace lodforge {

struct AssimpTexturing {
  // Per model material: the UV channel of its texture, or -1 when it has none usable.
  std::vector<int> uvChannel;

  bool textured(std::uint32_t material) const {
    return material < uvChannel.size() && uvChannel[material] >= 0;
  }
};

// `materialOf` maps the scene's materials to the model's (kNoMaterial: left out); the model's
// materials get their baseColorImage and wrap modes, its images what they use.
AssimpTexturing readAssimpTextures(const aiScene& scene, std::span<const std::uint32_t> materialOf,
                                   const std::string& path, Model& model,
                                   std::vector<std::string>* warnings);

}  // namespace lodforge
