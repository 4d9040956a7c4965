// A bound on the largest distance from a piece of a triangle (any triangle in space) to a mesh,
// with no sampling luck: the groundwork of issue 38's honest tile errors. Each piece corner's
// nearest triangle is found exactly; the distance to one triangle is convex, so over a convex
// piece it is largest at a corner, and cutting the piece into convex parts, each bounded through
// a triangle of its own, bounds the whole (any cut does; the ones chosen are tight near edges and
// vertices of the mesh).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/distance.h"
#include "lodforge/core/math.h"

namespace lodforge {

struct PieceBound {
  double lower = 0;  // the largest exact distance of the piece's corners (plus `carried`)
  double upper = 0;  // no point of the piece is farther from the mesh (plus `carried`)
  // The triangles the bound went through: every point of the piece is within `upper` of one.
  std::vector<std::uint32_t> used;
};

class PieceBounds {
 public:
  // The mesh (which must have a triangle); its arrays must outlive this. Triangles meeting at a
  // corner are found by position, so the mesh need not be welded.
  PieceBounds(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices);

  // By the corners' nearest triangles: one for all, its corners bound the piece (upper =
  // lower); otherwise the least of the best single corner triangle, and where they apply, two
  // sharing an edge (the piece cut by the plane bisecting their dihedral angle) and all around
  // one vertex (cut into angular sectors about the vertex's mean normal, each bounded through
  // the triangle spanning it).
  // With `carried` (a value per triangle of the mesh, or empty), a point bounded through
  // triangle t counts its distance plus carried[t]: a bound on a distance chained through t.
  PieceBound bound(const std::array<Vec3d, 3>& piece, std::span<const double> carried = {}) const;

 private:
  Vec3d corner(std::uint32_t triangle, int k) const;
  double distance(Vec3d p, std::uint32_t triangle, std::span<const double> carried) const;
  double edgeBound(const std::array<Vec3d, 3>& piece, std::uint32_t g, std::uint32_t h,
                   std::span<const double> carried) const;
  double vertexBound(const std::array<Vec3d, 3>& piece, std::uint32_t triangle, int k,
                     std::span<const double> carried, std::vector<std::uint32_t>& used) const;

  std::span<const Vec3f> positions_;
  std::span<const std::uint32_t> indices_;
  NearestTriangles nearest_;
  std::vector<std::uint32_t> cornersByPosition_;  // corner indices (3t + k), sorted by position
};

}  // namespace lodforge
