// A StreamBuffer's slots gathered in object order with the indices rebased: the compact layout
// of the CAD paper §3.3, which a GpuStream holds and a from-scratch build makes. Tests compare
// through it; slotsAreDisjoint checks the layout the view hides.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

#include "lodforge/runtime/stream.h"

namespace lodforge::test {

struct CompactView {
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<Vec2f> uvs;
  std::vector<std::uint32_t> source, indices;
};

inline CompactView compactView(const StreamBuffer& buffer) {
  CompactView view;
  const auto vertexStart = buffer.vertexStart(), triangleStart = buffer.triangleStart();
  const auto vertexCounts = buffer.vertexCounts(), triangleCounts = buffer.triangleCounts();
  const auto take = [](auto all, std::uint64_t start, std::uint64_t count, auto& into) {
    if (!all.empty()) into.insert(into.end(), all.begin() + start, all.begin() + start + count);
  };
  for (std::size_t i = 0; i < vertexCounts.size(); ++i) {
    const auto base = static_cast<std::uint32_t>(view.positions.size());
    take(buffer.positions(), vertexStart[i], vertexCounts[i], view.positions);
    take(buffer.normals(), vertexStart[i], vertexCounts[i], view.normals);
    take(buffer.colors(), vertexStart[i], vertexCounts[i], view.colors);
    take(buffer.uvs(), vertexStart[i], vertexCounts[i], view.uvs);
    take(buffer.sourceTriangles(), 3 * triangleStart[i], 3 * std::uint64_t{triangleCounts[i]},
         view.source);
    const std::size_t first = view.indices.size();
    take(buffer.indices(), 3 * triangleStart[i], 3 * std::uint64_t{triangleCounts[i]},
         view.indices);
    const auto shift = static_cast<std::uint32_t>(base - vertexStart[i]);  // mod 2^32
    for (std::size_t k = first; k < view.indices.size(); ++k) view.indices[k] += shift;
  }
  return view;
}

// slotOrder is a permutation of the objects whose held ranges, vertices and triangles, follow
// one another without overlap inside the arrays.
inline bool slotsAreDisjoint(const StreamBuffer& buffer) {
  const auto order = buffer.slotOrder();
  std::vector<std::uint32_t> sorted(order.begin(), order.end());
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::uint32_t> all(sorted.size());
  std::iota(all.begin(), all.end(), 0u);
  if (sorted != all || sorted.size() != buffer.vertexCounts().size()) return false;
  std::uint64_t vertexEnd = 0, triangleEnd = 0;
  for (const std::uint32_t i : order) {
    const std::uint32_t v = buffer.vertexCounts()[i], t = buffer.triangleCounts()[i];
    if (v && buffer.vertexStart()[i] < vertexEnd) return false;
    if (t && buffer.triangleStart()[i] < triangleEnd) return false;
    if (v) vertexEnd = buffer.vertexStart()[i] + v;
    if (t) triangleEnd = buffer.triangleStart()[i] + t;
  }
  return vertexEnd <= buffer.positions().size() && 3 * triangleEnd <= buffer.indices().size() &&
         buffer.positions().size() <= buffer.capacity().arenaVertices() &&
         buffer.indices().size() <= 3 * buffer.capacity().arenaTriangles();
}

}  // namespace lodforge::test
