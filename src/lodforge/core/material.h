// A part's material, as glTF 2.0 describes one (metallic-roughness PBR): what a reader found
// (glTF materials, OCCT's visual materials and transparency) and what tiles write per part.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace lodforge {

enum class AlphaMode : std::uint8_t { kOpaque, kMask, kBlend };
// What a texture does outside [0, 1] (glTF's sampler wrapS/wrapT).
enum class TextureWrap : std::uint8_t { kRepeat, kMirror, kClamp };

// A material without a base-colour texture (Material::baseColorImage).
inline constexpr std::uint32_t kNoImage = ~0u;

struct Material {
  std::string name;
  std::array<float, 4> baseColor{1, 1, 1, 1};  // linear RGBA (glTF's baseColorFactor)
  float metallic = 0;                          // CAD parts: dielectric unless the file says
  float roughness = 0.5f;
  AlphaMode alphaMode = AlphaMode::kOpaque;
  float alphaCutoff = 0.5f;  // kMask only
  bool doubleSided = false;
  std::array<float, 3> emissive{0, 0, 0};  // linear RGB
  // The base-colour texture (glTF's baseColorTexture, OBJ's map_Kd): into Model::images,
  // sampled at the model's uvs and multiplied by baseColor; kNoImage for none.
  std::uint32_t baseColorImage = kNoImage;
  TextureWrap wrapS = TextureWrap::kRepeat, wrapT = TextureWrap::kRepeat;

  bool operator==(const Material&) const = default;
};

// An object without a material (ObjectRecord::material).
inline constexpr std::uint32_t kNoMaterial = ~0u;
// Likewise for an object's CAD layer (Model::layers, a table beside the materials).
inline constexpr std::uint32_t kNoLayer = ~0u;

// glTF's name of an alpha mode ("OPAQUE", "MASK", "BLEND").
const char* alphaModeName(AlphaMode mode);
// glTF's sampler code of a wrap mode (10497 REPEAT, 33648 MIRRORED_REPEAT, 33071 CLAMP_TO_EDGE).
int wrapModeCode(TextureWrap wrap);
// The wrap mode of a glTF sampler code (REPEAT for an unknown one, glTF's default).
TextureWrap wrapModeOf(int code);

}  // namespace lodforge
