#include "lodforge/core/distance_bound.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>

namespace lodforge {
namespace {

constexpr double kTurn = 2 * std::numbers::pi;

bool positionLess(Vec3f a, Vec3f b) {
  return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
}

// A convex polygon of at most 8 corners: a triangle cut by a few planes.
struct Polygon {
  std::array<Vec3d, 8> corners;
  std::size_t count = 0;
};

// Keeps the part of `poly` where dot(x - o, n) >= 0 (a plane adds at most one corner).
void clipPolygon(Polygon& poly, Vec3d o, Vec3d n) {
  Polygon out;
  // A triangle cut by two planes has at most five corners.
  assert(poly.count + 1 <= out.corners.size());
  for (std::size_t i = 0; i < poly.count; ++i) {
    const Vec3d& a = poly.corners[i];
    const Vec3d& b = poly.corners[(i + 1) % poly.count];
    const double sa = dot(a - o, n), sb = dot(b - o, n);
    if (sa >= 0) out.corners[out.count++] = a;
    if ((sa > 0 && sb < 0) || (sa < 0 && sb > 0))
      out.corners[out.count++] = a + (b - a) * (sa / (sa - sb));
  }
  poly = out;
}

// A star triangle's angular span about the axis: from `from`, `width` radians counterclockwise.
struct Span {
  double from, width;
  std::uint32_t triangle;
};

// The span whose angles lie nearest `angle` (containing it when one does).
std::uint32_t spanningTriangle(std::span<const Span> spans, double angle) {
  std::uint32_t best = spans[0].triangle;
  double bestOff = std::numeric_limits<double>::max();
  for (const Span& s : spans) {
    double off = angle - s.from;  // both within a turn and a half of -pi
    while (off < -std::numbers::pi) off += kTurn;
    while (off >= std::numbers::pi) off -= kTurn;
    const double outside = off < 0 ? -off : off > s.width ? off - s.width : 0;
    if (outside < bestOff) {
      bestOff = outside;
      best = s.triangle;
    }
  }
  return best;
}

// The piece cut into the sectors between consecutive angles of `cuts` (about `axis` through v,
// angles measured from u towards w), each bounded through the star triangle spanning it.
// `distanceTo(x, t)` bounds a point through triangle t.
template <class Distance>
double sectorBound(const std::array<Vec3d, 3>& p, Vec3d v, Vec3d axis, Vec3d u, Vec3d w,
                   std::span<const double> angles, std::span<const Span> spans,
                   std::vector<std::uint32_t>& used, Distance distanceTo) {
  const auto direction = [&](double a) { return u * std::cos(a) + w * std::sin(a); };
  double worst = 0;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const double from = angles[i], to = i + 1 < angles.size() ? angles[i + 1] : angles[0] + kTurn;
    if (!(to > from)) continue;
    Polygon sector;
    for (const Vec3d& c : p) sector.corners[sector.count++] = c;
    clipPolygon(sector, v, cross(axis, direction(from)));
    if (sector.count == 0) continue;
    clipPolygon(sector, v, cross(direction(to), axis));
    if (sector.count == 0) continue;
    const std::uint32_t t = spanningTriangle(spans, (from + to) / 2);
    for (std::size_t c = 0; c < sector.count; ++c)
      worst = std::max(worst, distanceTo(sector.corners[c], t));
    if (std::find(used.begin(), used.end(), t) == used.end()) used.push_back(t);
  }
  return worst;
}

}  // namespace

PieceBounds::PieceBounds(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices)
    : positions_(positions), indices_(indices), nearest_(positions, indices) {
  cornersByPosition_.resize(indices.size());
  for (std::uint32_t i = 0; i < cornersByPosition_.size(); ++i) cornersByPosition_[i] = i;
  std::sort(cornersByPosition_.begin(), cornersByPosition_.end(),
            [&](std::uint32_t x, std::uint32_t y) {
              return positionLess(positions[indices[x]], positions[indices[y]]);
            });
}

Vec3d PieceBounds::corner(std::uint32_t triangle, int k) const {
  return toDouble(positions_[indices_[3 * std::size_t{triangle} + static_cast<std::size_t>(k)]]);
}

double PieceBounds::distance(Vec3d p, std::uint32_t t, std::span<const double> carried) const {
  return std::sqrt(pointTriangleDistanceSquared(p, corner(t, 0), corner(t, 1), corner(t, 2))) +
         (carried.empty() ? 0.0 : carried[t]);
}

PieceBound PieceBounds::bound(const std::array<Vec3d, 3>& p,
                              std::span<const double> carried) const {
  assert(carried.empty() || carried.size() == indices_.size() / 3);
  std::array<std::uint32_t, 3> f{};
  PieceBound out;
  for (std::size_t i = 0; i < 3; ++i) {
    const double d = std::sqrt(nearest_.nearestSquared(p[i], f[i]));
    out.lower = std::max(out.lower, d + (carried.empty() ? 0.0 : carried[f[i]]));
  }
  // All three corners nearest one triangle: their distances bound the piece (exact).
  if (f[0] == f[1] && f[1] == f[2]) {
    out.upper = out.lower;
    out.used = {f[0]};
    return out;
  }
  // Otherwise the least of: the best single corner triangle, and where they apply, the cut at
  // the plane bisecting a shared edge and the sectors around a shared vertex.
  out.upper = std::numeric_limits<double>::max();
  for (std::uint32_t t : f) {
    const double d = std::max(
        {distance(p[0], t, carried), distance(p[1], t, carried), distance(p[2], t, carried)});
    if (d < out.upper) {
      out.upper = d;
      out.used = {t};
    }
  }
  const std::uint32_t g = f[0], h = f[1] != g ? f[1] : f[2];
  if (f[1] == g || f[2] == g || f[1] == f[2]) {
    const double d = edgeBound(p, g, h, carried);
    if (d < out.upper) {
      out.upper = d;
      out.used = {g, h};
    }
  }
  for (int k = 0; k < 3; ++k) {
    const Vec3d v = corner(f[0], k);
    const auto has = [&](std::uint32_t t) {
      return v == corner(t, 0) || v == corner(t, 1) || v == corner(t, 2);
    };
    if (!has(f[1]) || !has(f[2])) continue;
    std::vector<std::uint32_t> used;
    const double d = vertexBound(p, f[0], k, carried, used);
    if (d < out.upper) {
      out.upper = d;
      out.used = std::move(used);
    }
    break;
  }
  return out;
}

// The piece cut by the plane through the shared edge that bisects the dihedral angle; each side
// bounded through its own triangle at its polygon's corners. Infinite when no edge is shared.
double PieceBounds::edgeBound(const std::array<Vec3d, 3>& p, std::uint32_t g, std::uint32_t h,
                              std::span<const double> carried) const {
  constexpr double kNone = std::numeric_limits<double>::max();
  std::array<Vec3d, 2> edge{};
  int shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (corner(g, i) == corner(h, j) && shared++ < 2)
        edge[static_cast<std::size_t>(shared - 1)] = corner(g, i);
  if (shared != 2) return kNone;
  const auto normalOf = [&](std::uint32_t t) {
    return normalizeOr(cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0)),
                       Vec3d{0, 0, 0});
  };
  const Vec3d ng = normalOf(g);
  Vec3d nh = normalOf(h);
  if (dot(ng, nh) < 0) nh = nh * -1.0;
  const Vec3d m = normalizeOr(cross(edge[1] - edge[0], ng + nh), Vec3d{0, 0, 0});
  if (m == Vec3d{0, 0, 0}) return kNone;
  const Vec3d gCentre = (corner(g, 0) + corner(g, 1) + corner(g, 2)) / 3.0;
  const double gSide = dot(m, gCentre - edge[0]) >= 0 ? 1.0 : -1.0;
  std::array<double, 3> s{};
  for (std::size_t i = 0; i < 3; ++i) s[i] = gSide * dot(m, p[i] - edge[0]);
  double worst = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    // A corner on the plane is a corner of both sides' polygons.
    if (s[i] >= 0) worst = std::max(worst, distance(p[i], g, carried));
    if (s[i] <= 0) worst = std::max(worst, distance(p[i], h, carried));
    const std::size_t j = (i + 1) % 3;
    if ((s[i] > 0 && s[j] < 0) || (s[i] < 0 && s[j] > 0)) {
      const Vec3d x = p[i] + (p[j] - p[i]) * (s[i] / (s[i] - s[j]));
      worst = std::max({worst, distance(x, g, carried), distance(x, h, carried)});
    }
  }
  return worst;
}

// Around corner k of `triangle` (vertex v): the triangles with a corner at v, the axis their
// summed normals, and the piece cut into sectors of a pencil of planes through the axis (which
// cover space) at every edge direction from v, gaps wider than a quarter turn cut into equal
// parts (so none is half a turn: each is convex); each sector bounded through the triangle
// spanning its middle direction.
double PieceBounds::vertexBound(const std::array<Vec3d, 3>& p, std::uint32_t triangle, int k,
                                std::span<const double> carried,
                                std::vector<std::uint32_t>& used) const {
  constexpr double kNone = std::numeric_limits<double>::max();
  const Vec3f key = positions_[indices_[3 * std::size_t{triangle} + static_cast<std::size_t>(k)]];
  const Vec3d v = toDouble(key);
  thread_local std::vector<std::uint32_t> star;
  thread_local std::vector<Span> spans;
  thread_local std::vector<double> cuts;
  star.clear();
  auto it = std::lower_bound(
      cornersByPosition_.begin(), cornersByPosition_.end(), key,
      [&](std::uint32_t c, Vec3f q) { return positionLess(positions_[indices_[c]], q); });
  for (; it != cornersByPosition_.end() && positions_[indices_[*it]] == key; ++it)
    star.push_back(*it / 3);
  Vec3d axis{0, 0, 0};
  for (std::uint32_t t : star)
    axis = axis + cross(corner(t, 1) - corner(t, 0), corner(t, 2) - corner(t, 0));
  axis = normalizeOr(axis, Vec3d{0, 0, 0});
  if (axis == Vec3d{0, 0, 0}) return kNone;
  const Vec3d u = normalizeOr(cross(axis, std::abs(axis.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}),
                              Vec3d{0, 0, 0});
  const Vec3d w = cross(axis, u);
  const auto angleOf = [&](Vec3d d) { return std::atan2(dot(d, w), dot(d, u)); };
  spans.clear();
  cuts.clear();
  for (std::uint32_t t : star) {
    std::array<double, 3> edges{};
    std::size_t n = 0;
    for (int c = 0; c < 3; ++c)
      if (corner(t, c) != v && n < 3) edges[n++] = angleOf(corner(t, c) - v);
    if (n != 2) continue;
    const double width = std::remainder(edges[1] - edges[0], kTurn);
    spans.push_back({width >= 0 ? edges[0] : edges[1], std::abs(width), t});
    cuts.push_back(edges[0]);
    cuts.push_back(edges[1]);
  }
  if (spans.empty()) return kNone;
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  // No sector as wide as half a turn (it would not be convex): a gap over a quarter turn is cut
  // into equal parts of at most a quarter.
  for (std::size_t i = 0, n = cuts.size(); i < n; ++i) {
    const double next = i + 1 < n ? cuts[i + 1] : cuts[0] + kTurn;
    const int parts = static_cast<int>(std::ceil((next - cuts[i]) / (kTurn / 4)));
    for (int q = 1; q < parts; ++q) cuts.push_back(cuts[i] + (next - cuts[i]) * q / parts);
  }
  std::sort(cuts.begin(), cuts.end());
  return sectorBound(p, v, axis, u, w, cuts, spans, used,
                     [&](Vec3d x, std::uint32_t t) { return distance(x, t, carried); });
}

}  // namespace lodforge
