// The signed distance at the grid's corners from oriented points (large-meshes paper §3.1's
// truncated signed distance): at a corner c, the weighted mean of the points' plane distances
// n·(c − p) over the points within `radius`, weights (1 − |c − p|²/r²)². No value (NaN) where
// fewer than `minPoints` points are that near: no surface bridges a hole.
//
// §3.3 makes the values of overlapping chunks identical by averaging them; here they are
// identical by construction: a corner's value depends only on the points within the radius,
// every chunk holds all of them (its overlap is at least the radius) and adds them in one order
// that is the same for every chunk (sumOrder), so two chunks compute the same bits. No value either
// past the edge of the points (DistanceOptions::edge).
#pragma once

#include <cstdint>
#include <span>

#include "lodforge/core/math.h"
#include "lodforge/surface/grid.h"

namespace lodforge {

struct OrientedPoints {
  std::span<const Vec3d> positions;
  std::span<const Vec3f> normals;      // unit, facing out
  std::span<const std::uint64_t> ids;  // index in the input
};

// The order in which a corner adds its points: by the Morton code of the lattice cell a point
// lies in, then by input index. It is one total order on the input, so every box adds a
// corner's points in the same order whichever of them it holds; and points near each other
// come together, so the corners they reach stay in cache. Returns the permutation of `ids`.
std::vector<std::uint32_t> sumOrder(const VoxelGrid& grid, std::span<const Vec3d> positions,
                                    std::span<const std::uint64_t> ids);

struct DistanceOptions {
  double radius = 3;  // in voxels
  std::uint32_t minPoints = 3;
  // Where the surface ends: a corner whose near points' weighted centroid lies farther from it
  // along their mean plane than this share of the radius has no value (beyond an open edge of
  // the scan every near point lies on one side, the centroid 0.3–0.4 radius away at the edge;
  // without this the surface would run on a radius past it; 0.4 already cut holes into a
  // closed sphere sampled at random, 0.5 did not).
  double edge = 0.5;
};

// Fills values.values for the box values.first/size, from points in an order that is the same
// for every box (sumOrder's, or ids ascending).
void signedDistances(const VoxelGrid& grid, const OrientedPoints& points,
                     const DistanceOptions& options, CornerValues& values);

}  // namespace lodforge
