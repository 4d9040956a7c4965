#include "lodforge/io/mesh/ply_objects.h"

#include <algorithm>

#include <fmt/format.h>

namespace lodforge {

void splitPlyObjects(Model& model, const std::vector<Vec3f>& positions,
                     const std::vector<Vec3f>& normals, const std::vector<Rgba8>& colors,
                     const std::vector<std::uint32_t>& triangles,
                     const std::vector<std::uint32_t>& triangleObjects) {
  const std::size_t triangleCount = triangleObjects.size();
  std::vector<std::uint32_t> order(triangleCount);
  for (std::uint32_t t = 0; t < triangleCount; ++t) order[t] = t;
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return triangleObjects[a] < triangleObjects[b];
  });
  std::vector<std::uint32_t> local(positions.size(), ~0u);
  std::vector<std::uint32_t> used;
  ModelBuilder builder(model);
  for (std::size_t begin = 0; begin < triangleCount;) {
    const std::uint32_t id = triangleObjects[order[begin]];
    std::size_t end = begin;
    while (end < triangleCount && triangleObjects[order[end]] == id) ++end;
    used.clear();
    for (std::size_t i = begin; i < end; ++i) {
      for (int k = 0; k < 3; ++k)
        used.push_back(triangles[3 * order[i] + static_cast<std::size_t>(k)]);
    }
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    builder.beginObject(fmt::format("object {}", id));
    for (std::size_t i = 0; i < used.size(); ++i) {
      local[used[i]] = static_cast<std::uint32_t>(i);
      model.positions.push_back(positions[used[i]]);
      if (!normals.empty()) model.normals.push_back(normals[used[i]]);
      if (!colors.empty()) model.colors.push_back(colors[used[i]]);
    }
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t t = order[i];
      model.indices.insert(
          model.indices.end(),
          {local[triangles[3 * t]], local[triangles[3 * t + 1]], local[triangles[3 * t + 2]]});
    }
    builder.endObject();
    begin = end;
  }
}

}  // namespace lodforge
