#include "lodforge/core/distance.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "lodforge/core/random.h"

namespace lodforge {

double pointTriangleDistanceSquared(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  auto squared = [&](Vec3d q) { return dot(p - q, p - q); };
  if (d1 <= 0 && d2 <= 0) return squared(a);
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return squared(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return squared(a + ab * (d1 / (d1 - d3)));
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return squared(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return squared(a + ac * (d2 / (d2 - d6)));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return squared(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  const double denominator = va + vb + vc;
  if (denominator <= 0) {  // degenerate triangle: nearest of the three edges' ends is good enough
    return std::min({squared(a), squared(b), squared(c)});
  }
  const double v = vb / denominator, w = vc / denominator;
  return squared(a + ab * v + ac * w);
}

Vec3d closestPointWeights(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  // pointTriangleDistanceSquared's Voronoi regions, answering with the point's weights.
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denominator = va + vb + vc;
  if (denominator <= 0) return {1, 0, 0};
  const double v = vb / denominator, w = vc / denominator;
  return {1 - v - w, v, w};
}

namespace detail {

// Triangles bucketed by the cells their bounding boxes touch; queries search growing shells of
// cells until no closer triangle can exist.
class TriangleGrid {
 public:
  // `queries`: about how many searches the grid will answer, when known. Beyond four cells per
  // triangle it gets up to eight per query (a million at most): for a batch of a few thousand,
  // building a million mostly empty cells cost more than the searches.
  TriangleGrid(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices,
               std::size_t queries = std::numeric_limits<std::size_t>::max())
      : positions_(positions), indices_(indices) {
    Aabb box;
    for (std::uint32_t i : indices) box.add(positions[i]);
    const std::size_t triangles = indices.size() / 3;
    origin_ = toDouble(box.min);
    const Vec3d size = triangles > 0 ? toDouble(box.max) - toDouble(box.min) : Vec3d{};
    // Cells about twice the typical triangle's size: a few triangles per non-empty cell whether
    // the mesh fills a volume or lies on a surface (a volume-based size puts dozens of a flat
    // scan's triangles in every cell, or spreads a flat mesh's few big triangles over a million).
    // The typical size from at most ~8K evenly spread triangles: the grid only has to be about
    // right (queries are exact whatever its size), and building it is most of a query batch.
    const std::size_t stride = std::max<std::size_t>(1, triangles / 8192);
    double area = 0;
    std::size_t measured = 0;
    for (std::size_t i = 0; i < triangles; i += stride, ++measured) {
      const auto t = static_cast<std::uint32_t>(i);
      area += 0.5 * length(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
    }
    if (triangles > 0 && area > 0) {
      cell_ = 2 * std::sqrt(area / static_cast<double>(measured));
    } else {
      const double volume =
          std::max(size.x, 1e-12) * std::max(size.y, 1e-12) * std::max(size.z, 1e-12);
      cell_ = std::cbrt(volume / std::max<double>(1, static_cast<double>(triangles) / 2));
    }
    cell_ = std::max({cell_, box.longestSide() / 1024.0, 1e-9});
    // Keep the grid within a few cells per triangle (flat or sparse meshes would explode it).
    const double maxCells = std::max(1.0, 4.0 * static_cast<double>(triangles) +
                                              std::min(1e6, 8.0 * static_cast<double>(queries)));
    while (true) {
      // Clamped before the conversion (a NaN clamps to 1024).
      for (int k = 0; k < 3; ++k)
        dims_[k] = std::max(1, static_cast<int>(std::min(1024.0, std::ceil(size[k] / cell_))));
      if (static_cast<double>(dims_[0]) * dims_[1] * dims_[2] <= maxCells) break;
      cell_ *= 1.26;
    }
    const std::size_t cells = static_cast<std::size_t>(dims_[0]) *
                              static_cast<std::size_t>(dims_[1]) *
                              static_cast<std::size_t>(dims_[2]);
    const std::vector<VertexCell> vertexCells = placeVertices();
    // Counting sort of (cell, triangle) pairs. Most triangles lie in one cell: that cell is kept
    // from the counting pass, the few that span more are visited again.
    constexpr std::uint32_t kSpans = ~0u;
    std::vector<std::uint32_t> single(triangles);
    start_.assign(cells + 1, 0);
    for (std::uint32_t t = 0; t < triangles; ++t) {
      const CellRange r = cellRange(vertexCells, t);
      if (r.x0 == r.x1 && r.y0 == r.y1 && r.z0 == r.z1) {
        const auto cell = static_cast<std::uint32_t>(index(r.x0, r.y0, r.z0));
        single[t] = cell;
        ++start_[cell];
      } else {
        single[t] = kSpans;
        forEachCell(r, [&](std::size_t cell) { ++start_[cell]; });
      }
    }
    // Inclusive sums: start_[c] is where cell c ends; filling backwards (last triangle first)
    // moves it to where c starts, with each cell's triangles in increasing order.
    for (std::size_t i = 1; i < cells; ++i) start_[i] += start_[i - 1];
    start_[cells] = cells > 0 ? start_[cells - 1] : 0;
    items_.resize(start_[cells]);
    for (std::uint32_t t = static_cast<std::uint32_t>(triangles); t-- > 0;) {
      if (single[t] != kSpans) {
        items_[--start_[single[t]]] = t;
      } else {
        forEachCell(cellRange(vertexCells, t),
                    [&](std::size_t cell) { items_[--start_[cell]] = t; });
      }
    }
  }

  // The squared distance from p to the nearest triangle, or any value not above `enough` as soon
  // as one is found (a maximum over many queries needs nothing more from a query below it);
  // that triangle in `nearest` when given.
  double nearestSquared(Vec3d p, double enough = -1, std::uint32_t* nearest = nullptr) const {
    const int cx = clampCell(0, p.x), cy = clampCell(1, p.y), cz = clampCell(2, p.z);
    double best = std::numeric_limits<double>::max();
    const int maxRing = std::max({dims_[0], dims_[1], dims_[2]});
    for (int ring = 0; ring <= maxRing; ++ring) {
      // The shell of cells exactly `ring` away, clipped to the grid (a flat grid has one layer).
      const int z0 = std::max(cz - ring, 0), z1 = std::min(cz + ring, dims_[2] - 1);
      const int y0 = std::max(cy - ring, 0), y1 = std::min(cy + ring, dims_[1] - 1);
      const int x0 = std::max(cx - ring, 0), x1 = std::min(cx + ring, dims_[0] - 1);
      const auto visit = [&](int x, int y, int z) {
        // A cell whose box is already farther than the best triangle holds nothing closer.
        if (boxDistanceSquared(p, x, y, z) >= best) return false;
        const std::size_t cell = index(x, y, z);
        for (std::uint32_t i = start_[cell]; i < start_[cell + 1]; ++i) {
          const std::uint32_t t = items_[i];
          const double d =
              pointTriangleDistanceSquared(p, corner(t, 0), corner(t, 1), corner(t, 2));
          if (nearest != nullptr && d < best) *nearest = t;
          best = std::min(best, d);
          if (best <= enough) return true;
        }
        return false;
      };
      for (int z = z0; z <= z1; ++z) {
        for (int y = y0; y <= y1; ++y) {
          if (std::abs(z - cz) == ring || std::abs(y - cy) == ring) {
            for (int x = x0; x <= x1; ++x)
              if (visit(x, y, z)) return best;
          } else {
            if (cx - ring >= 0 && visit(cx - ring, y, z)) return best;
            if (ring > 0 && cx + ring < dims_[0] && visit(cx + ring, y, z)) return best;
          }
        }
      }
      // Anything not searched yet lies outside the block of cells within `ring`: at least as
      // far as p is from the block's nearest inner face (faces on the grid's edge have
      // nothing beyond them).
      double reach = std::numeric_limits<double>::infinity();
      const int c[3] = {cx, cy, cz};
      for (int axis = 0; axis < 3; ++axis) {
        if (c[axis] - ring > 0)
          reach = std::min(reach, p[axis] - (origin_[axis] + (c[axis] - ring) * cell_));
        if (c[axis] + ring < dims_[axis] - 1)
          reach = std::min(reach, origin_[axis] + (c[axis] + ring + 1) * cell_ - p[axis]);
      }
      if (best < std::numeric_limits<double>::max() && (reach < 0 ? 0 : reach * reach) >= best)
        break;
    }
    return best;
  }

 private:
  double boxDistanceSquared(Vec3d p, int x, int y, int z) const {
    const int c[3] = {x, y, z};
    double sum = 0;
    for (int axis = 0; axis < 3; ++axis) {
      // Edge cells reach out without end: they hold whatever clamping put there.
      const double low = origin_[axis] + c[axis] * cell_;
      const double below = c[axis] > 0 ? low - p[axis] : 0.0;
      const double above = c[axis] < dims_[axis] - 1 ? p[axis] - (low + cell_) : 0.0;
      const double d = std::max({below, 0.0, above});
      sum += d * d;
    }
    return sum;
  }
  Vec3d corner(std::uint32_t t, int k) const {
    return toDouble(positions_[indices_[3 * t + static_cast<std::size_t>(k)]]);
  }
  // Each position's cell once (a vertex is on about six triangles): a triangle's cells are the
  // box of its corners' cells, which is its bounding box's (clampCell never decreases).
  using VertexCell = std::array<std::uint16_t, 3>;
  std::vector<VertexCell> placeVertices() const {
    std::vector<VertexCell> cells(positions_.size());
    for (std::size_t v = 0; v < positions_.size(); ++v) {
      const Vec3f p = positions_[v];
      cells[v] = {static_cast<std::uint16_t>(clampCell(0, p.x)),
                  static_cast<std::uint16_t>(clampCell(1, p.y)),
                  static_cast<std::uint16_t>(clampCell(2, p.z))};
    }
    return cells;
  }
  // Clamped before the conversion: a point far outside the grid (a query, an unused vertex)
  // or a NaN must not overflow an int.
  int clampCell(int axis, double v) const {
    const double cell = std::floor((v - origin_[axis]) / cell_);
    if (!(cell > 0)) return 0;
    return cell >= dims_[axis] - 1 ? dims_[axis] - 1 : static_cast<int>(cell);
  }
  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * static_cast<std::size_t>(dims_[1]) +
            static_cast<std::size_t>(y)) *
               static_cast<std::size_t>(dims_[0]) +
           static_cast<std::size_t>(x);
  }
  struct CellRange {
    int x0, x1, y0, y1, z0, z1;
  };
  // The cells triangle t's bounding box touches.
  CellRange cellRange(std::span<const VertexCell> cells, std::uint32_t t) const {
    const VertexCell& a = cells[indices_[3 * std::size_t{t}]];
    const VertexCell& b = cells[indices_[3 * std::size_t{t} + 1]];
    const VertexCell& c = cells[indices_[3 * std::size_t{t} + 2]];
    return {std::min({a[0], b[0], c[0]}), std::max({a[0], b[0], c[0]}),
            std::min({a[1], b[1], c[1]}), std::max({a[1], b[1], c[1]}),
            std::min({a[2], b[2], c[2]}), std::max({a[2], b[2], c[2]})};
  }
  template <class Fn>
  void forEachCell(const CellRange& r, Fn&& fn) const {
    for (int z = r.z0; z <= r.z1; ++z)
      for (int y = r.y0; y <= r.y1; ++y)
        for (int x = r.x0; x <= r.x1; ++x) fn(index(x, y, z));
  }

  std::span<const Vec3f> positions_;
  std::span<const std::uint32_t> indices_;
  Vec3d origin_;
  double cell_ = 1;
  int dims_[3] = {1, 1, 1};
  std::vector<std::uint32_t> start_, items_;
};

}  // namespace detail

NearestTriangles::NearestTriangles(std::span<const Vec3f> positions,
                                   std::span<const std::uint32_t> indices)
    : grid_(std::make_unique<detail::TriangleGrid>(positions, indices)) {}

NearestTriangles::~NearestTriangles() = default;

double NearestTriangles::nearestSquared(Vec3d p, std::uint32_t& triangle) const {
  return grid_->nearestSquared(p, -1, &triangle);
}

namespace {

using detail::TriangleGrid;

// Area-uniform sample points on a mesh.
std::vector<Vec3d> samplePoints(std::span<const Vec3f> positions,
                                std::span<const std::uint32_t> indices, std::uint32_t count,
                                std::uint64_t seed, bool corners) {
  const std::size_t triangles = indices.size() / 3;
  std::vector<double> cumulative(triangles);
  double total = 0;
  auto corner = [&](std::size_t t, int k) {
    return toDouble(positions[indices[3 * t + static_cast<std::size_t>(k)]]);
  };
  for (std::size_t t = 0; t < triangles; ++t) {
    total += 0.5 * length(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
    cumulative[t] = total;
  }
  std::vector<Vec3d> points;
  if (triangles == 0 || total <= 0) return points;
  points.reserve(count + (corners ? triangles : 0));
  // Every triangle's corners too, so the distance never misses a vertex's excursion.
  if (corners) {
    for (std::size_t t = 0; t < triangles; ++t) points.push_back(corner(t, 0));
  }
  Random random(seed);
  for (std::uint32_t i = 0; i < count; ++i) {
    const double pick = random.uniform() * total;
    const std::size_t t = static_cast<std::size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin());
    double r1 = random.uniform(), r2 = random.uniform();
    if (r1 + r2 > 1) {
      r1 = 1 - r1;
      r2 = 1 - r2;
    }
    const std::size_t tt = std::min(t, triangles - 1);
    points.push_back(corner(tt, 0) + (corner(tt, 1) - corner(tt, 0)) * r1 +
                     (corner(tt, 2) - corner(tt, 0)) * r2);
  }
  return points;
}

struct OneSided {
  double max = 0, sumSquares = 0, sum = 0;
  std::size_t count = 0;
  std::size_t farthest = 0;  // the first sample at `max`
};

// The largest of the points' distances to the grid's triangles (exact: a query stops early only
// when it can no longer exceed the largest found so far).
double farthest(const std::vector<Vec3d>& points, const TriangleGrid& grid) {
  return std::sqrt(tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, points.size(), 1024), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double worst) {
        for (std::size_t i = range.begin(); i < range.end(); ++i)
          worst = std::max(worst, grid.nearestSquared(points[i], worst));
        return worst;
      },
      [](double a, double b) { return std::max(a, b); }));
}

OneSided measure(const std::vector<Vec3d>& points, const TriangleGrid& grid) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, points.size(), 1024), OneSided{},
      [&](const tbb::blocked_range<std::size_t>& range, OneSided acc) {
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
          const double squared = grid.nearestSquared(points[i]);
          const double d = std::sqrt(squared);
          if (d > acc.max || acc.count == 0) {
            acc.max = d;
            acc.farthest = i;
          }
          acc.sumSquares += squared;
          acc.sum += d;
          ++acc.count;
        }
        return acc;
      },
      [](OneSided a, const OneSided& b) {
        // The first of equal distances in sample order, however the range was split.
        if (b.count &&
            (a.count == 0 || b.max > a.max || (b.max == a.max && b.farthest < a.farthest))) {
          a.max = b.max;
          a.farthest = b.farthest;
        }
        a.sumSquares += b.sumSquares;
        a.sum += b.sum;
        a.count += b.count;
        return a;
      });
}

}  // namespace

SurfaceDistance surfaceDistance(std::span<const Vec3f> positionsA,
                                std::span<const std::uint32_t> indicesA,
                                std::span<const Vec3f> positionsB,
                                std::span<const std::uint32_t> indicesB,
                                std::uint32_t samplesPerMesh, std::uint64_t seed, bool corners) {
  SurfaceDistance result;
  if (indicesA.empty() || indicesB.empty()) {
    result.hausdorff = result.rms = std::numeric_limits<double>::infinity();
    result.maxAB = result.maxBA = result.hausdorff;
    return result;
  }
  const TriangleGrid gridA(positionsA, indicesA), gridB(positionsB, indicesB);
  const std::vector<Vec3d> onA = samplePoints(positionsA, indicesA, samplesPerMesh, seed, corners);
  const std::vector<Vec3d> onB =
      samplePoints(positionsB, indicesB, samplesPerMesh, seed + 1, corners);
  const OneSided ab = measure(onA, gridB), ba = measure(onB, gridA);
  result.hausdorff = std::max(ab.max, ba.max);
  result.maxAB = ab.max;
  result.maxBA = ba.max;
  // (No samples where a mesh's triangles have no area: its farthest point stays at 0.)
  if (!onA.empty()) result.farthestOnA = onA[ab.farthest];
  if (!onB.empty()) result.farthestOnB = onB[ba.farthest];
  result.rms = std::sqrt((ab.sumSquares + ba.sumSquares) /
                         static_cast<double>(std::max<std::size_t>(1, ab.count + ba.count)));
  result.meanAB = ab.sum / static_cast<double>(std::max<std::size_t>(1, ab.count));
  result.meanBA = ba.sum / static_cast<double>(std::max<std::size_t>(1, ba.count));
  return result;
}

double sampledHausdorff(std::span<const Vec3f> positionsA, std::span<const std::uint32_t> indicesA,
                        std::span<const Vec3f> positionsB, std::span<const std::uint32_t> indicesB,
                        std::uint32_t samplesPerMesh, std::uint64_t seed, bool corners) {
  if (indicesA.empty() || indicesB.empty()) return std::numeric_limits<double>::infinity();
  const std::vector<Vec3d> onA = samplePoints(positionsA, indicesA, samplesPerMesh, seed, corners);
  const double ab = farthest(onA, TriangleGrid(positionsB, indicesB, onA.size()));
  const std::vector<Vec3d> onB =
      samplePoints(positionsB, indicesB, samplesPerMesh, seed + 1, corners);
  const double ba = farthest(onB, TriangleGrid(positionsA, indicesA, onB.size()));
  return std::max(ab, ba);
}

double farthestDistance(std::span<const Vec3f> points, std::span<const Vec3f> positions,
                        std::span<const std::uint32_t> indices) {
  if (points.empty()) return 0;
  if (indices.empty()) return std::numeric_limits<double>::infinity();
  const TriangleGrid grid(positions, indices);
  std::vector<Vec3d> wide(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) wide[i] = toDouble(points[i]);
  return measure(wide, grid).max;
}

namespace {

// A sample on A's textured triangles: where it is, its texture and texture coordinate there.
struct TexturedSample {
  Vec3d point;
  std::uint32_t texture;
  Vec2f uv;
};

std::vector<TexturedSample> textureSamples(const TexturedSurface& s, std::uint32_t count,
                                           std::uint64_t seed) {
  const std::size_t triangles = s.indices.size() / 3;
  const auto corner = [&](std::size_t t, std::size_t k) {
    return toDouble(s.positions[s.indices[3 * t + k]]);
  };
  std::vector<double> cumulative(triangles);
  double total = 0;
  for (std::size_t t = 0; t < triangles; ++t) {
    if (s.texture[t] != ~0u)
      total += 0.5 * length(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)));
    cumulative[t] = total;
  }
  std::vector<TexturedSample> out;
  if (total <= 0) return out;
  Random random(seed);
  for (std::uint32_t i = 0; i < count; ++i) {
    const double pick = random.uniform() * total;
    const std::size_t t = std::min<std::size_t>(
        triangles - 1,
        static_cast<std::size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), pick) -
                                 cumulative.begin()));
    double r1 = random.uniform(), r2 = random.uniform();
    if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
    const Vec2f a = s.uvs[s.indices[3 * t]], b = s.uvs[s.indices[3 * t + 1]],
                c = s.uvs[s.indices[3 * t + 2]];
    out.push_back(
        {corner(t, 0) + (corner(t, 1) - corner(t, 0)) * r1 + (corner(t, 2) - corner(t, 0)) * r2,
         s.texture[t],
         {static_cast<float>(a.x + (b.x - a.x) * r1 + (c.x - a.x) * r2),
          static_cast<float>(a.y + (b.y - a.y) * r1 + (c.y - a.y) * r2)}});
  }
  return out;
}

}  // namespace

TextureDistance textureDistance(const TexturedSurface& a, const TexturedSurface& b,
                                std::uint32_t samples, std::uint64_t seed) {
  assert(a.texture.size() == a.indices.size() / 3 && b.texture.size() == b.indices.size() / 3);
  TextureDistance result;
  const std::vector<TexturedSample> points = textureSamples(a, samples, seed);
  if (points.empty() || b.indices.empty()) return result;
  const TriangleGrid grid(b.positions, b.indices);
  // Per sample: its distance in texels, or -1 where B has another texture there.
  std::vector<double> texels(points.size());
  tbb::parallel_for(std::size_t{0}, points.size(), [&](std::size_t i) {
    const TexturedSample& p = points[i];
    std::uint32_t t = 0;
    grid.nearestSquared(p.point, -1, &t);
    if (b.texture[t] != p.texture) {
      texels[i] = -1;
      return;
    }
    const auto at = [&](std::size_t k) { return b.indices[3 * std::size_t{t} + k]; };
    const Vec3d w = closestPointWeights(p.point, toDouble(b.positions[at(0)]),
                                        toDouble(b.positions[at(1)]), toDouble(b.positions[at(2)]));
    const Vec2f u0 = b.uvs[at(0)], u1 = b.uvs[at(1)], u2 = b.uvs[at(2)];
    const double du = (w.x * u0.x + w.y * u1.x + w.z * u2.x - p.uv.x) * a.texels[p.texture][0];
    const double dv = (w.x * u0.y + w.y * u1.y + w.z * u2.y - p.uv.y) * a.texels[p.texture][1];
    texels[i] = std::hypot(du, dv);
  });
  std::vector<double> same;
  for (double d : texels) (d < 0 ? result.otherTexture : result.samples) += 1;
  for (double d : texels)
    if (d >= 0) same.push_back(d);
  if (same.empty()) return result;
  std::sort(same.begin(), same.end());
  double sum = 0;
  for (double d : same) sum += d;
  result.mean = sum / static_cast<double>(same.size());
  result.median = same[same.size() / 2];
  result.p95 = same[std::min(same.size() - 1, same.size() * 95 / 100)];
  result.max = same.back();
  return result;
}

}  // namespace lodforge
