// The signed distance at the grid's corners from oriented points (large-meshes paper §3.1's
// truncated signed distance): at a corner c, the weighted mean of the points' plane distances
// n·(c − p) over the points within `radius`, weights (1 − |c − p|²/r²)². No value (NaN) where
// fewer than `minPoints` points are that near: no surface bridges a hole.
//
// §3.3 makes the values of overlapping chunks identical by averaging them; here they are
// identical by construction: a corner's value depends only on the points within the radius,
// every chunk holds all of them (its overlap is at least the radius) and adds them in one order
// that is the same for every chunk (input order), so two chunks compute the same bits. No value
// either past the edge of the points (DistanceOptions::edge).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/surface/grid.h"

namespace lodforge {

struct OrientedPoints {
  std::span<const Vec3d> positions;  // in input order: the order every box adds them in
  std::span<const Vec3f> normals;    // unit, facing out
};

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

// The sums behind a box's corner values, filled a point at a time: a chunk's points can be
// streamed through it from a file, and split by rows of corners between threads (each row adds
// the same points in the same order whichever thread owns it).
class CornerSums {
 public:
  CornerSums(const VoxelGrid& grid, const DistanceOptions& options,
             std::array<std::uint64_t, 3> first, std::array<std::uint32_t, 3> size);
  // Adds a point (in input order) to the box's corners within the radius whose row (y index in
  // the box) is in [rowFirst, rowEnd).
  void add(Vec3d at, Vec3f normal, std::uint32_t rowFirst, std::uint32_t rowEnd);
  void add(Vec3d at, Vec3f normal) { add(at, normal, 0, size_[1]); }
  std::uint32_t rows() const { return size_[1]; }
  // The values: NaN where fewer than minPoints points are near or past the edge of the points.
  CornerValues values() const;

 private:
  // One corner's sums side by side: a point's update touches one cache line per corner.
  struct Sums {
    double weight = 0, sum = 0;
    Vec3f offset, direction;  // Σ w (p − c), Σ w n (only compared)
    std::uint32_t near = 0;
  };
  const VoxelGrid& grid_;
  DistanceOptions options_;
  std::array<std::uint64_t, 3> first_;
  std::array<std::uint32_t, 3> size_;
  std::vector<Sums> corners_;
};

// Fills values.values for the box values.first/size from the points (CornerSums in one go).
void signedDistances(const VoxelGrid& grid, const OrientedPoints& points,
                     const DistanceOptions& options, CornerValues& values);

}  // namespace lodforge
