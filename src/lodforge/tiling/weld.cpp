#include "lodforge/tiling/weld.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "lodforge/core/position_hash.h"

namespace lodforge {

void weldExact(MeshPart& mesh) {
  // A mesh of no objects (a scan: chunk records always carry the field) keeps no features.
  if (std::all_of(mesh.features.begin(), mesh.features.end(),
                  [](std::uint32_t f) { return f == kNoFeature; }))
    mesh.features.clear();
  const std::uint32_t count = mesh.vertexCount();
  // Each vertex points at the first vertex (lowest index) with its position: an open-addressing
  // table keyed by position, filled in vertex order.
  std::size_t capacity = 16;
  while (capacity < 2 * std::size_t{count}) capacity *= 2;
  std::vector<std::uint32_t> table(capacity, ~0u);
  std::vector<std::uint32_t> representative(count);
  const bool features = !mesh.features.empty();
  const bool textured = !mesh.uvs.empty();
  const auto featureOf = [&](std::uint32_t v) { return features ? mesh.features[v] : kNoFeature; };
  // Texture coordinates and material must match too: a UV seam stays two vertices.
  const auto sameTexel = [&](std::uint32_t a, std::uint32_t b) {
    return !textured || (mesh.uvs[a] == mesh.uvs[b] && mesh.materials[a] == mesh.materials[b]);
  };
  for (std::uint32_t v = 0; v < count; ++v) {
    const Vec3d& p = mesh.positions[v];
    const std::uint32_t feature = featureOf(v);
    std::size_t slot = (hashExactPosition(p) ^ feature * 0x9E3779B97F4A7C15ull) & (capacity - 1);
    while (table[slot] != ~0u && !(mesh.positions[table[slot]] == p &&
                                   featureOf(table[slot]) == feature && sameTexel(table[slot], v)))
      slot = (slot + 1) & (capacity - 1);
    if (table[slot] == ~0u) table[slot] = v;
    representative[v] = table[slot];
  }
  // Triangles over representatives; drop those that repeat a corner.
  std::size_t kept = 0;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t a = representative[mesh.indices[t]],
                        b = representative[mesh.indices[t + 1]],
                        c = representative[mesh.indices[t + 2]];
    if (a == b || b == c || a == c) continue;
    mesh.indices[kept++] = a, mesh.indices[kept++] = b, mesh.indices[kept++] = c;
  }
  mesh.indices.resize(kept);
  // Renumber the used vertices in order of first use.
  std::vector<std::uint32_t> remap(count, ~0u);
  std::uint32_t next = 0;
  for (std::uint32_t& v : mesh.indices) {
    if (remap[v] == ~0u) remap[v] = next++;
    v = remap[v];
  }
  std::vector<Vec3d> positions(next);
  std::vector<Rgba8> colors(mesh.colors.empty() ? 0 : next);
  std::vector<Vec3f> normals(mesh.normals.empty() ? 0 : next);
  std::vector<std::uint32_t> featureOfVertex(features ? next : 0);
  std::vector<Vec2f> uvs(textured ? next : 0);
  std::vector<std::uint32_t> materials(textured ? next : 0);
  // The members of each group whose normals were summed, as a list through `summedNext`.
  std::vector<std::uint32_t> summedHead(normals.empty() ? 0 : next, ~0u);
  std::vector<std::uint32_t> summedNext(normals.empty() ? 0 : count, ~0u);
  for (std::uint32_t v = 0; v < count; ++v) {
    // Distinct normals of a group are averaged (a part's hard edge, split in the input, meets
    // here); a normal seen already in the group is the same vertex stored again.
    const std::uint32_t to = remap[representative[v]];
    if (to != ~0u && !normals.empty()) {
      bool seen = false;
      for (std::uint32_t m = summedHead[to]; m != ~0u && !seen; m = summedNext[m])
        seen = mesh.normals[m] == mesh.normals[v];
      if (!seen) {
        normals[to] = normals[to] + mesh.normals[v];
        summedNext[v] = summedHead[to];
        summedHead[to] = v;
      }
    }
    if (remap[v] == ~0u) continue;  // not a representative, or unused
    positions[remap[v]] = mesh.positions[v];
    if (!colors.empty()) colors[remap[v]] = mesh.colors[v];
    if (features) featureOfVertex[remap[v]] = mesh.features[v];
    if (textured) {
      uvs[remap[v]] = mesh.uvs[v];
      materials[remap[v]] = mesh.materials[v];
    }
  }
  for (std::size_t v = 0; v < normals.size(); ++v)
    normals[v] = normalizeOr(normals[v], Vec3f{0, 0, 1});
  mesh.positions = std::move(positions);
  mesh.colors = std::move(colors);
  mesh.normals = std::move(normals);
  mesh.features = std::move(featureOfVertex);
  mesh.uvs = std::move(uvs);
  mesh.materials = std::move(materials);
}

}  // namespace lodforge
