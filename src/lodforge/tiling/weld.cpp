#include "lodforge/tiling/weld.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "lodforge/core/position_hash.h"

namespace lodforge {

namespace {

// Per vertex, the first vertex (lowest index) with its position, part and, textured, texture
// coordinate and material: an open-addressing table keyed by position, filled in vertex order.
std::vector<std::uint32_t> firstEqualVertex(const MeshPart& mesh) {
  const std::uint32_t count = mesh.vertexCount();
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
  return representative;
}

// Triangles over representatives, those that repeat a corner dropped; the used vertices
// renumbered in order of first use. Returns each vertex's new number (~0u: none).
std::vector<std::uint32_t> renumberUsed(MeshPart& mesh,
                                        std::span<const std::uint32_t> representative,
                                        std::uint32_t& next) {
  std::size_t kept = 0;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t a = representative[mesh.indices[t]],
                        b = representative[mesh.indices[t + 1]],
                        c = representative[mesh.indices[t + 2]];
    if (a == b || b == c || a == c) continue;
    mesh.indices[kept++] = a, mesh.indices[kept++] = b, mesh.indices[kept++] = c;
  }
  mesh.indices.resize(kept);
  std::vector<std::uint32_t> remap(mesh.vertexCount(), ~0u);
  next = 0;
  for (std::uint32_t& v : mesh.indices) {
    if (remap[v] == ~0u) remap[v] = next++;
    v = remap[v];
  }
  return remap;
}

// Each group's normal: its distinct normals averaged (a part's hard edge, split in the input,
// meets here); a normal seen already in the group is the same vertex stored again.
std::vector<Vec3f> groupNormals(const MeshPart& mesh, std::span<const std::uint32_t> representative,
                                std::span<const std::uint32_t> remap, std::uint32_t next) {
  std::vector<Vec3f> normals(next);
  // The members of each group whose normals were summed, as a list through `summedNext`.
  std::vector<std::uint32_t> summedHead(next, ~0u), summedNext(mesh.vertexCount(), ~0u);
  for (std::uint32_t v = 0; v < mesh.vertexCount(); ++v) {
    const std::uint32_t to = remap[representative[v]];
    if (to == ~0u) continue;
    bool seen = false;
    for (std::uint32_t m = summedHead[to]; m != ~0u && !seen; m = summedNext[m])
      seen = mesh.normals[m] == mesh.normals[v];
    if (!seen) {
      normals[to] = normals[to] + mesh.normals[v];
      summedNext[v] = summedHead[to];
      summedHead[to] = v;
    }
  }
  for (Vec3f& n : normals) n = normalizeOr(n, Vec3f{0, 0, 1});
  return normals;
}

// out[remap[v]] = in[v] for the representatives (the first vertex of a group keeps its value).
template <class T>
void keepRepresentatives(std::vector<T>& values, std::span<const std::uint32_t> remap,
                         std::uint32_t next) {
  if (values.empty()) return;
  std::vector<T> out(next);
  for (std::size_t v = 0; v < remap.size(); ++v)
    if (remap[v] != ~0u) out[remap[v]] = values[v];
  values = std::move(out);
}

}  // namespace

void weldExact(MeshPart& mesh) {
  // A mesh of no objects (a scan: chunk records always carry the field) keeps no features.
  if (std::all_of(mesh.features.begin(), mesh.features.end(),
                  [](std::uint32_t f) { return f == kNoFeature; }))
    mesh.features.clear();
  const std::vector<std::uint32_t> representative = firstEqualVertex(mesh);
  std::uint32_t next = 0;
  const std::vector<std::uint32_t> remap = renumberUsed(mesh, representative, next);
  if (!mesh.normals.empty()) mesh.normals = groupNormals(mesh, representative, remap, next);
  keepRepresentatives(mesh.positions, remap, next);
  keepRepresentatives(mesh.colors, remap, next);
  keepRepresentatives(mesh.features, remap, next);
  keepRepresentatives(mesh.uvs, remap, next);
  keepRepresentatives(mesh.materials, remap, next);
}

}  // namespace lodforge
