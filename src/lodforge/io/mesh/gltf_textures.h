// A glTF's base-colour textures (pbrMetallicRoughness.baseColorTexture): each material's image
// (embedded in a bufferView or a data URI, or a file beside the glTF; EXT_texture_webp's source
// too), its sampler's wrap modes, which TEXCOORD set it reads and its KHR_texture_transform.
// An image that cannot be found or read is a warning naming it, and its material draws without
// it.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "lodforge/core/model.h"

namespace lodforge {

struct GltfTexturing {
  // Per material: the TEXCOORD set its texture reads, or -1 when it has no usable texture.
  std::vector<int> texCoord;
  // Per material: KHR_texture_transform as the affine map uv' = (a u + b v + c, d u + e v + f).
  std::vector<std::array<double, 6>> transform;

  bool textured(int material) const {
    return material >= 0 && static_cast<std::size_t>(material) < texCoord.size() &&
           texCoord[static_cast<std::size_t>(material)] >= 0;
  }
  // (A result beyond a float's range is no coordinate: 0.)
  Vec2f apply(int material, double u, double v) const {
    const auto& t = transform[static_cast<std::size_t>(material)];
    const auto fit = [](double x) { return std::abs(x) < 1e30 ? static_cast<float>(x) : 0.0f; };
    return {fit(t[0] * u + t[1] * v + t[2]), fit(t[3] * u + t[4] * v + t[5])};
  }
};

// Sets `model.materials` (already read, one per glTF material) baseColorImage and wrap modes and
// appends the images they use to `model.images`. `baseDir` is where external images lie (empty:
// none may be read); `name` the glTF file, for messages.
GltfTexturing readGltfTextures(const tinygltf::Model& gltf, const std::string& baseDir,
                               const std::string& name, Model& model,
                               std::vector<std::string>* warnings);

// tinygltf's image callback: keeps the bytes of a data-URI image (undecoded) in image->image,
// where readGltfTextures finds them; decodes nothing.
bool keepEncodedImage(tinygltf::Image* image, int index, std::string* error, std::string* warning,
                      int width, int height, const unsigned char* bytes, int size, void* user);

}  // namespace lodforge
