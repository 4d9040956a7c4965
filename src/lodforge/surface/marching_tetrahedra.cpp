#include "lodforge/surface/marching_tetrahedra.h"

#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <utility>

namespace lodforge {

namespace {

// Freudenthal's six tetrahedra of a cell: the paths from corner 000 to 111 along the axes in
// every order. Corners as bit sets (bit 0: +x, 1: +y, 2: +z); along a path they only grow, so
// every tetrahedron edge runs from a lower to a higher corner in one of the seven directions.
constexpr std::array<std::array<int, 4>, 6> kTetrahedra = {
    {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}}};

struct Cell {
  std::array<std::uint64_t, 3> corner;  // global index of its corner 000
  std::array<float, 8> values;
};

// The gradient of the values at a global corner: central differences, one-sided where a
// neighbour is unknown or outside the box, 0 along an axis with neither.
Vec3d gradientAt(const CornerValues& values, std::array<std::uint64_t, 3> at) {
  std::array<std::uint32_t, 3> local{};
  for (std::size_t a = 0; a < 3; ++a)
    local[a] = static_cast<std::uint32_t>(at[a] - values.first[a]);
  const double here = values.values[values.index(local[0], local[1], local[2])];
  Vec3d g;
  for (std::size_t a = 0; a < 3; ++a) {
    const auto valueAt = [&](int step) {
      std::array<std::uint32_t, 3> q = local;
      if ((step < 0 && q[a] == 0) || (step > 0 && q[a] + 1 >= values.size[a]))
        return std::numeric_limits<double>::quiet_NaN();
      q[a] = static_cast<std::uint32_t>(static_cast<std::int64_t>(q[a]) + step);
      return static_cast<double>(values.values[values.index(q[0], q[1], q[2])]);
    };
    const double below = valueAt(-1), above = valueAt(1);
    double d = 0;
    if (!std::isnan(below) && !std::isnan(above)) {
      d = (above - below) / 2;
    } else if (!std::isnan(above)) {
      d = above - here;
    } else if (!std::isnan(below)) {
      d = here - below;
    }
    g[static_cast<int>(a)] = d;
  }
  return g;
}

class Polygonizer {
 public:
  Polygonizer(const VoxelGrid& grid, const CornerValues& values, SurfacePiece& out)
      : grid_(grid), values_(values), out_(out) {}

  void cell(const Cell& c) {
    for (const auto& tet : kTetrahedra) tetrahedron(c, tet);
  }

 private:
  // The vertex on the edge from cell corner `a` to `b` (a ⊂ b as bit sets), made once.
  std::uint32_t vertex(const Cell& c, int a, int b) {
    const std::uint64_t i = c.corner[0] + (a & 1), j = c.corner[1] + ((a >> 1) & 1),
                        k = c.corner[2] + ((a >> 2) & 1);
    const std::uint64_t key = edgeKey(grid_, i, j, k, a ^ b);
    const auto [at, added] = vertexOf_.try_emplace(key, static_cast<std::uint32_t>(0));
    if (!added) return at->second;
    // From the lower corner always: both chunks that hold the edge compute the same bits.
    const double va = c.values[static_cast<std::size_t>(a)],
                 vb = c.values[static_cast<std::size_t>(b)];
    const double t = va / (va - vb);
    const Vec3d p = grid_.position(i, j, k);
    const std::array<std::uint64_t, 3> upper = {c.corner[0] + (b & 1), c.corner[1] + ((b >> 1) & 1),
                                                c.corner[2] + ((b >> 2) & 1)};
    const Vec3d q = grid_.position(upper[0], upper[1], upper[2]);
    at->second = static_cast<std::uint32_t>(out_.positions.size());
    out_.positions.push_back(p + (q - p) * t);
    const Vec3d gradient =
        gradientAt(values_, {i, j, k}) * (1 - t) + gradientAt(values_, upper) * t;
    out_.normals.push_back(toFloat(normalizeOr(gradient, Vec3d{0, 0, 1})));
    out_.edges.push_back(key);
    return at->second;
  }

  Vec3d cornerPosition(const Cell& c, int corner) const {
    return grid_.position(c.corner[0] + (corner & 1), c.corner[1] + ((corner >> 1) & 1),
                          c.corner[2] + ((corner >> 2) & 1));
  }

  // A triangle facing from the negative corners towards the positive ones.
  void triangle(const Cell& c, std::array<std::uint32_t, 3> v, const std::array<int, 4>& tet) {
    Vec3d inside, outside;
    for (int corner : tet) {
      (c.values[static_cast<std::size_t>(corner)] < 0 ? inside : outside) =
          (c.values[static_cast<std::size_t>(corner)] < 0 ? inside : outside) +
          cornerPosition(c, corner);
    }
    const Vec3d& p0 = out_.positions[v[0]];
    const Vec3d normal = cross(out_.positions[v[1]] - p0, out_.positions[v[2]] - p0);
    // Sums stand for centroids here: only the sign of the dot product matters, and each side
    // has between one and three corners, so weigh them alike.
    int in = 0;
    for (int corner : tet) in += c.values[static_cast<std::size_t>(corner)] < 0 ? 1 : 0;
    const Vec3d towards = outside * (1.0 / (4 - in)) - inside * (1.0 / in);
    if (dot(normal, towards) < 0) std::swap(v[1], v[2]);
    out_.indices.insert(out_.indices.end(), v.begin(), v.end());
  }

  void tetrahedron(const Cell& c, const std::array<int, 4>& tet) {
    std::array<int, 4> in{}, out{};
    int ins = 0, outs = 0;
    for (int corner : tet) {
      if (c.values[static_cast<std::size_t>(corner)] < 0) {
        in[static_cast<std::size_t>(ins++)] = corner;
      } else {
        out[static_cast<std::size_t>(outs++)] = corner;
      }
    }
    if (ins == 0 || outs == 0) return;
    // An edge between corners a and b, named from the lower one.
    const auto on = [&](int a, int b) { return a < b ? vertex(c, a, b) : vertex(c, b, a); };
    if (ins == 1 || outs == 1) {
      const int lone = ins == 1 ? in[0] : out[0];
      const std::array<int, 4>& rest = ins == 1 ? out : in;
      triangle(c, {on(lone, rest[0]), on(lone, rest[1]), on(lone, rest[2])}, tet);
      return;
    }
    // Two and two: a quad, as two triangles.
    const std::uint32_t a = on(in[0], out[0]), b = on(in[0], out[1]), d = on(in[1], out[1]),
                        e = on(in[1], out[0]);
    triangle(c, {a, b, d}, tet);
    triangle(c, {a, d, e}, tet);
  }

  const VoxelGrid& grid_;
  const CornerValues& values_;
  SurfacePiece& out_;
  std::unordered_map<std::uint64_t, std::uint32_t> vertexOf_;
};

}  // namespace

std::uint64_t edgeKey(const VoxelGrid& grid, std::uint64_t i, std::uint64_t j, std::uint64_t k,
                      int d) {
  assert(d >= 1 && d <= 7);
  assert(i < grid.corners[0] && j < grid.corners[1] && k < grid.corners[2]);
  return ((k * grid.corners[1] + j) * grid.corners[0] + i) * 7 + static_cast<std::uint64_t>(d - 1);
}

SurfacePiece polygonize(const VoxelGrid& grid, const CornerValues& values,
                        std::array<std::uint64_t, 3> first, std::array<std::uint32_t, 3> size) {
  assert(values.values.size() ==
         static_cast<std::size_t>(values.size[0]) * values.size[1] * values.size[2]);
  SurfacePiece out;
  Polygonizer polygonizer(grid, values, out);
  if (size[0] == 0) {
    first = values.first;
    size = values.size;
  }
  for (std::size_t a = 0; a < 3; ++a)
    assert(size[a] > 0 && first[a] >= values.first[a] &&
           first[a] - values.first[a] + size[a] <= values.size[a]);
  std::array<std::uint32_t, 3> lo{}, hi{};  // the cells' corner 000, local to `values`
  for (std::size_t a = 0; a < 3; ++a) {
    lo[a] = static_cast<std::uint32_t>(first[a] - values.first[a]);
    hi[a] = lo[a] + size[a] - 1;
  }
  for (std::uint32_t k = lo[2]; k < hi[2]; ++k) {
    for (std::uint32_t j = lo[1]; j < hi[1]; ++j) {
      for (std::uint32_t i = lo[0]; i < hi[0]; ++i) {
        Cell cell{{values.first[0] + i, values.first[1] + j, values.first[2] + k}, {}};
        bool known = true, negative = false, positive = false;
        for (int corner = 0; corner < 8; ++corner) {
          const float v =
              values.values[values.index(i + static_cast<std::uint32_t>(corner & 1),
                                         j + static_cast<std::uint32_t>((corner >> 1) & 1),
                                         k + static_cast<std::uint32_t>((corner >> 2) & 1))];
          known = known && !std::isnan(v);
          negative = negative || v < 0;
          positive = positive || v >= 0;
          cell.values[static_cast<std::size_t>(corner)] = v;
        }
        if (known && negative && positive) polygonizer.cell(cell);
      }
    }
  }
  return out;
}

}  // namespace lodforge
