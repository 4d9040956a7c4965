#include "lodforge/tiling/chunk_grid.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <utility>

namespace lodforge {

ChunkGrid ChunkGrid::over(const Aabbd& bounds, double size) {
  assert(!bounds.empty() && size > 0);
  ChunkGrid grid;
  grid.origin = bounds.min;
  grid.size = size;
  const Vec3d extent = bounds.size();
  for (int axis = 0; axis < 3; ++axis) {
    const double cells = std::ceil(extent[axis] / size);
    grid.dims[static_cast<std::size_t>(axis)] =
        static_cast<std::int32_t>(std::clamp(cells, 1.0, double{1 << 20}));
  }
  return grid;
}

double ChunkGrid::sizeFor(const Aabbd& bounds, std::uint64_t triangles,
                          std::uint64_t trianglesPerChunk) {
  std::array<double, 3> sides = {bounds.size().x, bounds.size().y, bounds.size().z};
  std::sort(sides.begin(), sides.end());
  const double longest = std::max(sides[2], 1e-9);
  if (triangles <= trianglesPerChunk) return longest;
  // A surface: the triangles spread over about the two largest sides' area.
  const double area = std::max(sides[1], longest * 1e-3) * longest;
  const double size =
      std::sqrt(area * static_cast<double>(trianglesPerChunk) / static_cast<double>(triangles));
  return std::clamp(size, longest / 4096, longest);
}

ChunkCell ChunkGrid::cellOf(Vec3d p) const {
  ChunkCell cell{};
  for (int axis = 0; axis < 3; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    const double k = std::floor((p[axis] - origin[axis]) / size);
    cell[a] = static_cast<std::int32_t>(std::clamp(k, 0.0, static_cast<double>(dims[a] - 1)));
  }
  return cell;
}

Aabbd ChunkGrid::cellBounds(const ChunkCell& cell) const {
  Aabbd box;
  box.min = {plane(0, cell[0]), plane(1, cell[1]), plane(2, cell[2])};
  box.max = {plane(0, cell[0] + 1), plane(1, cell[1] + 1), plane(2, cell[2] + 1)};
  return box;
}

namespace {

using Polygon = std::vector<CutCorner>;

bool lexicographicallyBefore(const Vec3d& a, const Vec3d& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

// Where edge p-q meets the plane: from the edge's ends in a fixed order, so the two triangles on
// the edge (which walk it in opposite directions) compute the same bits.
CutCorner crossing(const CutCorner& p, const CutCorner& q, int axis, double coordinate) {
  const bool pFirst = lexicographicallyBefore(p.position, q.position);
  const CutCorner& a = pFirst ? p : q;
  const CutCorner& b = pFirst ? q : p;
  const double t = (coordinate - a.position[axis]) / (b.position[axis] - a.position[axis]);
  CutCorner out;
  out.position = a.position + (b.position - a.position) * t;
  out.position[axis] = coordinate;
  const auto lerp = [t](std::uint8_t from, std::uint8_t to) {
    return static_cast<std::uint8_t>(std::lround(from + (to - from) * t));
  };
  out.color = {lerp(a.color.r, b.color.r), lerp(a.color.g, b.color.g), lerp(a.color.b, b.color.b),
               lerp(a.color.a, b.color.a)};
  const auto f = static_cast<float>(t);
  out.normal = normalizeOr(a.normal + (b.normal - a.normal) * f, a.normal);
  out.feature = a.feature;
  out.uv = {a.uv.x + (b.uv.x - a.uv.x) * f, a.uv.y + (b.uv.y - a.uv.y) * f};
  out.material = a.material;
  return out;
}

// Sutherland–Hodgman against one plane: `below` keeps coordinate <= c, `above` >= c (corners on
// the plane go to both), in the polygon's winding.
void split(const Polygon& polygon, int axis, double coordinate, Polygon& below, Polygon& above) {
  below.clear();
  above.clear();
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const CutCorner& current = polygon[i];
    const CutCorner& next = polygon[(i + 1) % polygon.size()];
    const double dc = current.position[axis] - coordinate;
    const double dn = next.position[axis] - coordinate;
    if (dc <= 0) below.push_back(current);
    if (dc >= 0) above.push_back(current);
    if ((dc < 0 && dn > 0) || (dc > 0 && dn < 0)) {
      const CutCorner x = crossing(current, next, axis, coordinate);
      below.push_back(x);
      above.push_back(x);
    }
  }
}

// The grid planes of `axis` that may pass through [low, high] (the grid's outer faces never
// cut): callers still test each strictly inside.
std::pair<std::int32_t, std::int32_t> innerPlanes(const ChunkGrid& grid, int axis, double low,
                                                  double high) {
  const auto a = static_cast<std::size_t>(axis);
  const auto first =
      static_cast<std::int32_t>(std::max(1.0, std::floor((low - grid.origin[axis]) / grid.size)));
  const auto last =
      static_cast<std::int32_t>(std::min(static_cast<double>(grid.dims[a] - 1),
                                         std::floor((high - grid.origin[axis]) / grid.size) + 1));
  return {first, last};
}

struct Emitter {
  const ChunkGrid& grid;
  std::vector<ChunkCell>& cells;
  std::vector<CutCorner>& corners;

  void emit(const Polygon& polygon) {
    // Repeated corners (a cut through a corner) would make degenerate pieces.
    Polygon unique;
    for (const CutCorner& c : polygon) {
      if (unique.empty() || unique.back().position != c.position) unique.push_back(c);
    }
    while (unique.size() > 1 && unique.front().position == unique.back().position)
      unique.pop_back();
    if (unique.size() < 3) return;
    Vec3d sum{};
    Vec3f normalSum{};
    std::array<double, 4> colorSum{};
    double uSum = 0, vSum = 0;
    for (const CutCorner& c : unique) {
      sum = sum + c.position;
      uSum += c.uv.x, vSum += c.uv.y;
      normalSum = normalSum + c.normal;
      colorSum[0] += c.color.r, colorSum[1] += c.color.g;
      colorSum[2] += c.color.b, colorSum[3] += c.color.a;
    }
    const double n = static_cast<double>(unique.size());
    const CutCorner centroid{sum / n,
                             {static_cast<std::uint8_t>(std::lround(colorSum[0] / n)),
                              static_cast<std::uint8_t>(std::lround(colorSum[1] / n)),
                              static_cast<std::uint8_t>(std::lround(colorSum[2] / n)),
                              static_cast<std::uint8_t>(std::lround(colorSum[3] / n))},
                             normalizeOr(normalSum, unique[0].normal),
                             CutCorner::kNoSource,
                             unique[0].feature,
                             {static_cast<float>(uSum / n), static_cast<float>(vSum / n)},
                             unique[0].material};
    const ChunkCell cell = grid.cellOf(centroid.position);
    if (unique.size() == 3) {
      if (!hasArea(unique[0], unique[1], unique[2])) return;
      cells.push_back(cell);
      corners.insert(corners.end(), unique.begin(), unique.end());
      return;
    }
    fan(unique, centroid, cell);
  }

  // A piece of a convex triangle is convex: n − 2 triangles fanned from a corner none of whose
  // triangles is flat (a cut on an edge leaves corners in line), else n around the centroid.
  // The fan adds no corner on an edge, so the pieces still meet without T-junctions.
  void fan(const Polygon& piece, const CutCorner& centroid, ChunkCell cell) {
    const std::size_t count = piece.size();
    for (std::size_t k = 0; k < count; ++k) {
      bool flat = false;
      for (std::size_t i = 1; i + 1 < count && !flat; ++i)
        flat = !hasArea(piece[k], piece[(k + i) % count], piece[(k + i + 1) % count]);
      if (flat) continue;
      for (std::size_t i = 1; i + 1 < count; ++i) {
        cells.push_back(cell);
        corners.push_back(piece[k]);
        corners.push_back(piece[(k + i) % count]);
        corners.push_back(piece[(k + i + 1) % count]);
      }
      return;
    }
    for (std::size_t i = 0; i < count; ++i) {
      cells.push_back(cell);
      corners.push_back(centroid);
      corners.push_back(piece[i]);
      corners.push_back(piece[(i + 1) % count]);
    }
  }

  static bool hasArea(const CutCorner& a, const CutCorner& b, const CutCorner& c) {
    const Vec3d normal = cross(b.position - a.position, c.position - a.position);
    return normal.x != 0 || normal.y != 0 || normal.z != 0;
  }

  // Cuts at the planes of `axis` inside the polygon, then the next axis for each part.
  void cut(const Polygon& polygon, int axis) {
    if (axis == 3) {
      emit(polygon);
      return;
    }
    double low = polygon[0].position[axis], high = low;
    for (const CutCorner& c : polygon) {
      low = std::min(low, c.position[axis]);
      high = std::max(high, c.position[axis]);
    }
    const auto [first, last] = innerPlanes(grid, axis, low, high);
    Polygon rest = polygon, below, above;
    for (std::int32_t k = first; k <= last; ++k) {
      const double coordinate = grid.plane(axis, k);
      if (coordinate <= low || coordinate >= high) continue;
      split(rest, axis, coordinate, below, above);
      if (below.size() >= 3) cut(below, axis + 1);
      rest.swap(above);
      if (rest.size() < 3) return;
    }
    cut(rest, axis + 1);
  }
};

// True when no grid plane passes strictly between the triangle's corners on any axis, which
// is when Emitter::cut splits nothing (the same test, plane by plane).
bool insideOneCell(const ChunkGrid& grid, const std::array<CutCorner, 3>& triangle) {
  for (int axis = 0; axis < 3; ++axis) {
    const double low = std::min(
        {triangle[0].position[axis], triangle[1].position[axis], triangle[2].position[axis]});
    const double high = std::max(
        {triangle[0].position[axis], triangle[1].position[axis], triangle[2].position[axis]});
    const auto [first, last] = innerPlanes(grid, axis, low, high);
    for (std::int32_t k = first; k <= last; ++k) {
      const double coordinate = grid.plane(axis, k);
      if (coordinate > low && coordinate < high) return false;
    }
  }
  return true;
}

}  // namespace

void cutTriangle(const ChunkGrid& grid, const std::array<CutCorner, 3>& triangle,
                 std::vector<ChunkCell>& cells, std::vector<CutCorner>& corners) {
  if (!insideOneCell(grid, triangle)) {
    Emitter emitter{grid, cells, corners};
    emitter.cut(Polygon(triangle.begin(), triangle.end()), 0);
    return;
  }
  // Most triangles: what Emitter::emit does with an uncut triangle, without its polygons.
  const Vec3d &a = triangle[0].position, &b = triangle[1].position, &c = triangle[2].position;
  if (a == b || b == c || a == c) return;  // a repeated corner: no piece
  const Vec3d normal = cross(b - a, c - a);
  if (normal.x == 0 && normal.y == 0 && normal.z == 0) return;  // no area
  // The centroid summed as emit sums it, so the cell is the same bit for bit.
  cells.push_back(grid.cellOf((((Vec3d{} + a) + b) + c) / 3.0));
  corners.insert(corners.end(), triangle.begin(), triangle.end());
}

}  // namespace lodforge
