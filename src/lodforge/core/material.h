// A part's material, as glTF 2.0 describes one (metallic-roughness PBR): what a reader found
// (glTF materials, OCCT's visual materials and transparency) and what tiles write per part.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace lodforge {

enum class AlphaMode : std::uint8_t { kOpaque, kMask, kBlend };

struct Material {
  std::string name;
  std::array<float, 4> baseColor{1, 1, 1, 1};  // linear RGBA (glTF's baseColorFactor)
  float metallic = 0;                          // CAD parts: dielectric unless the file says
  float roughness = 0.5f;
  AlphaMode alphaMode = AlphaMode::kOpaque;
  float alphaCutoff = 0.5f;  // kMask only
  bool doubleSided = false;
  std::array<float, 3> emissive{0, 0, 0};  // linear RGB

  bool operator==(const Material&) const = default;
};

// An object without a material (ObjectRecord::material).
inline constexpr std::uint32_t kNoMaterial = ~0u;
// Likewise for an object's CAD layer (Model::layers, a table beside the materials).
inline constexpr std::uint32_t kNoLayer = ~0u;

// glTF's name of an alpha mode ("OPAQUE", "MASK", "BLEND").
const char* alphaModeName(AlphaMode mode);

}  // namespace lodforge
