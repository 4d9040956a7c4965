#include "lodforge/core/mesh.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numeric>
#include <vector>

#include "lodforge/core/position_hash.h"

namespace lodforge {

Aabb computeBounds(std::span<const Vec3f> positions) {
  Aabb box;
  for (const Vec3f& p : positions) box.add(p);
  return box;
}

namespace {

using Cell = std::array<std::int64_t, 3>;

std::uint64_t hashCell(const Cell& c) {
  // 64-bit mix of the three coordinates (splitmix-style finaliser on a combined key).
  std::uint64_t h = static_cast<std::uint64_t>(c[0]) * 0x9E3779B97F4A7C15ull;
  h ^= static_cast<std::uint64_t>(c[1]) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
  h ^= static_cast<std::uint64_t>(c[2]) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 29;
  return h;
}

// Welding groups vertices by key: the exact position, or the epsilon grid cell. A flat
// open-addressing table maps a key, by its hash, to the first representative with it; further
// representatives of the same key (attribute splits) chain through `next`.
class KeyTable {
 public:
  explicit KeyTable(std::size_t expected) {
    std::size_t capacity = 16;
    while (capacity < expected * 2) capacity *= 2;
    slots_.assign(capacity, kEmpty);
    mask_ = capacity - 1;
  }
  // Returns the slot holding the key of `hash` that `sameKey(representative)` recognises (its
  // value is kEmpty when the key is new).
  template <class SameKey>
  std::uint32_t& find(std::uint64_t hash, const SameKey& sameKey) {
    std::size_t i = hash & mask_;
    while (slots_[i] != kEmpty && !sameKey(slots_[i])) i = (i + 1) & mask_;
    return slots_[i];
  }
  static constexpr std::uint32_t kEmpty = ~0u;

 private:
  std::vector<std::uint32_t> slots_;
  std::size_t mask_ = 0;
};

// The keys of welding: with epsilon 0 a vertex's exact position (-0 == +0), else its cell in a
// grid of epsilon-sized cells; and the representatives of each key.
class WeldKeys {
 public:
  WeldKeys(std::span<const Vec3f> positions, float epsilon)
      : positions_(positions),
        exact_(epsilon == 0.0f),
        inverseCell_(exact_ ? 0.0 : 1.0 / epsilon),
        table_(positions.size()) {}
  bool exact() const { return exact_; }
  Cell cellOf(std::uint32_t v) const {
    const Vec3f p = positions_[v];
    return {static_cast<std::int64_t>(std::floor(p.x * inverseCell_)),
            static_cast<std::int64_t>(std::floor(p.y * inverseCell_)),
            static_cast<std::int64_t>(std::floor(p.z * inverseCell_))};
  }
  // The first representative of v's exact position, or of the grid cell `probe`.
  std::uint32_t& first(std::uint32_t v, const Cell& probe) {
    if (exact_) {
      return table_.find(hashExactPosition(positions_[v]),
                         [&](std::uint32_t r) { return positions_[r] == positions_[v]; });
    }
    return table_.find(hashCell(probe), [&](std::uint32_t r) { return cellOf(r) == probe; });
  }

 private:
  std::span<const Vec3f> positions_;
  bool exact_;
  double inverseCell_;
  KeyTable table_;
};

}  // namespace

std::uint32_t weldVertices(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                           std::span<const Rgba8> colors, const WeldOptions& options,
                           std::span<std::uint32_t> remap, std::span<const Vec2f> uvs) {
  assert(remap.size() == positions.size());
  assert(uvs.empty() || uvs.size() == positions.size());
  assert(!options.keepNormalSplits || normals.size() == positions.size());
  assert(!options.keepColorSplits || colors.size() == positions.size());
  assert(options.epsilon >= 0.0f);

  WeldKeys keys(positions, options.epsilon);
  const bool exact = keys.exact();
  const float epsilonSquared = options.epsilon * options.epsilon;
  const float cosLimit =
      static_cast<float>(std::cos(options.normalAngleDegrees * 3.14159265358979323846 / 180.0));

  auto attributesMatch = [&](std::uint32_t a, std::uint32_t b) {
    if (options.keepColorSplits && colors[a] != colors[b]) return false;
    if (!uvs.empty() && uvs[a] != uvs[b]) return false;
    if (options.keepNormalSplits) {
      const Vec3f na = normalizeOr(normals[a], Vec3f{});
      const Vec3f nb = normalizeOr(normals[b], Vec3f{});
      if (dot(na, nb) < cosLimit) return false;
    }
    return true;
  };
  auto positionsMatch = [&](std::uint32_t a, std::uint32_t b) {
    if (exact) return true;  // the same exact key is the same position
    const Vec3f d = positions[a] - positions[b];
    return dot(d, d) <= epsilonSquared;
  };

  const auto vertexCount = static_cast<std::uint32_t>(positions.size());
  std::vector<std::uint32_t> next(positions.size(), KeyTable::kEmpty);
  std::uint32_t newCount = 0;

  for (std::uint32_t v = 0; v < vertexCount; ++v) {
    const Cell cell = exact ? Cell{} : keys.cellOf(v);
    std::uint32_t match = KeyTable::kEmpty;
    // Exact welding looks up the vertex's own position; epsilon welding the 27 cells around it.
    const int reach = exact ? 0 : 1;
    for (int dx = -reach; dx <= reach && match == KeyTable::kEmpty; ++dx) {
      for (int dy = -reach; dy <= reach && match == KeyTable::kEmpty; ++dy) {
        for (int dz = -reach; dz <= reach && match == KeyTable::kEmpty; ++dz) {
          const Cell probe{cell[0] + dx, cell[1] + dy, cell[2] + dz};
          for (std::uint32_t r = keys.first(v, probe); r != KeyTable::kEmpty; r = next[r]) {
            if (positionsMatch(v, r) && attributesMatch(v, r)) {
              match = r;
              break;
            }
          }
        }
      }
    }
    if (match != KeyTable::kEmpty) {
      remap[v] = remap[match];
      continue;
    }
    remap[v] = newCount++;
    std::uint32_t& head = keys.first(v, cell);
    // Append to the end of the chain so earlier representatives are preferred.
    if (head == KeyTable::kEmpty) {
      head = v;
    } else {
      std::uint32_t last = head;
      while (next[last] != KeyTable::kEmpty) last = next[last];
      next[last] = v;
    }
  }
  return newCount;
}

void remapIndices(std::span<std::uint32_t> indices, std::span<const std::uint32_t> remap) {
  for (std::uint32_t& i : indices) i = remap[i];
}

std::size_t removeDegenerateTriangles(std::span<const Vec3f> positions,
                                      std::span<std::uint32_t> indices,
                                      const DegenerateOptions& options) {
  assert(indices.size() % 3 == 0);
  std::size_t kept = 0;
  for (std::size_t t = 0; t < indices.size() / 3; ++t) {
    const std::uint32_t a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
    if (a == b || b == c || a == c) continue;
    if (options.zeroArea) {
      const Vec3f n = cross(positions[b] - positions[a], positions[c] - positions[a]);
      if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f) continue;
    }
    indices[3 * kept] = a;
    indices[3 * kept + 1] = b;
    indices[3 * kept + 2] = c;
    ++kept;
  }
  return kept;
}

void computeVertexNormals(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices,
                          std::span<Vec3f> normals) {
  assert(normals.size() == positions.size());
  std::fill(normals.begin(), normals.end(), Vec3f{});
  for (std::size_t t = 0; t < indices.size() / 3; ++t) {
    const std::uint32_t a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
    // The unnormalised cross product weights each face by its area.
    const Vec3f n = cross(positions[b] - positions[a], positions[c] - positions[a]);
    normals[a] += n;
    normals[b] += n;
    normals[c] += n;
  }
  for (Vec3f& n : normals) n = normalizeOr(n, Vec3f{0, 0, 1});
}

namespace {
std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];  // path halving
    v = parent[v];
  }
  return v;
}
}  // namespace

std::uint32_t connectedComponents(std::uint32_t vertexCount, std::span<const std::uint32_t> indices,
                                  std::span<std::uint32_t> triangleComponent) {
  assert(triangleComponent.size() == indices.size() / 3);
  std::vector<std::uint32_t> parent(vertexCount);
  std::iota(parent.begin(), parent.end(), 0u);
  for (std::size_t t = 0; t < indices.size() / 3; ++t) {
    for (std::size_t k = 1; k < 3; ++k) {
      // Roots again each time: the previous union may have moved the first corner's root.
      const std::uint32_t a = findRoot(parent, indices[3 * t]);
      const std::uint32_t b = findRoot(parent, indices[3 * t + k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<std::uint32_t> label(vertexCount, ~0u);
  std::uint32_t count = 0;
  for (std::size_t t = 0; t < indices.size() / 3; ++t) {
    const std::uint32_t root = findRoot(parent, indices[3 * t]);
    if (label[root] == ~0u) label[root] = count++;
    triangleComponent[t] = label[root];
  }
  return count;
}

std::uint32_t findReferencedVertices([[maybe_unused]] std::uint32_t vertexCount,
                                     std::span<const std::uint32_t> indices,
                                     std::span<std::uint32_t> remap) {
  assert(remap.size() == vertexCount);
  std::fill(remap.begin(), remap.end(), 0u);
  for (std::uint32_t i : indices) remap[i] = 1;
  std::uint32_t kept = 0;
  for (std::uint32_t& r : remap) r = r ? kept++ : ~0u;
  return kept;
}

std::uint64_t countBoundaryEdges(std::span<const std::uint32_t> indices) {
  // Sort undirected edges and count those that occur once.
  std::vector<std::uint64_t> edges;
  edges.reserve(indices.size());
  for (std::size_t t = 0; t < indices.size() / 3; ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint64_t a = indices[3 * t + k], b = indices[3 * t + (k + 1) % 3];
      edges.push_back(std::min(a, b) << 32 | std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::uint64_t boundary = 0;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) ++boundary;
    i = j;
  }
  return boundary;
}

}  // namespace lodforge
