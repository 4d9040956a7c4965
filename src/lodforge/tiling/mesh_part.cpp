#include "lodforge/tiling/mesh_part.h"

#include <algorithm>

namespace lodforge {

std::vector<std::uint32_t> distinctFeatures(const MeshPart& mesh) {
  std::vector<std::uint32_t> out(mesh.features);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  if (!out.empty() && out.back() == kNoFeature) out.pop_back();
  return out;
}

MeshPart concatenate(std::span<const MeshPart> parts) {
  MeshPart out;
  const bool colors =
      std::any_of(parts.begin(), parts.end(), [](const MeshPart& p) { return !p.colors.empty(); });
  const bool normals =
      std::any_of(parts.begin(), parts.end(), [](const MeshPart& p) { return !p.normals.empty(); });
  const bool features = std::any_of(parts.begin(), parts.end(),
                                    [](const MeshPart& p) { return !p.features.empty(); });
  const bool textured =
      std::any_of(parts.begin(), parts.end(), [](const MeshPart& p) { return !p.uvs.empty(); });
  for (const MeshPart& part : parts) {
    const std::uint32_t base = out.vertexCount();
    out.positions.insert(out.positions.end(), part.positions.begin(), part.positions.end());
    if (colors) {
      if (part.colors.empty()) {
        out.colors.resize(out.positions.size(), Rgba8{255, 255, 255, 255});
      } else {
        out.colors.insert(out.colors.end(), part.colors.begin(), part.colors.end());
      }
    }
    if (normals) {
      if (part.normals.empty()) {
        out.normals.resize(out.positions.size(), Vec3f{0, 0, 1});
      } else {
        out.normals.insert(out.normals.end(), part.normals.begin(), part.normals.end());
      }
    }
    if (features) {
      if (part.features.empty()) {
        out.features.resize(out.positions.size(), kNoFeature);
      } else {
        out.features.insert(out.features.end(), part.features.begin(), part.features.end());
      }
    }
    if (textured) {
      if (part.uvs.empty()) {
        out.uvs.resize(out.positions.size());
        out.materials.resize(out.positions.size(), ~0u);
      } else {
        out.uvs.insert(out.uvs.end(), part.uvs.begin(), part.uvs.end());
        out.materials.insert(out.materials.end(), part.materials.begin(), part.materials.end());
      }
    }
    for (std::uint32_t i : part.indices) out.indices.push_back(base + i);
  }
  return out;
}

}  // namespace lodforge
