// The signed distance at the grid's corners from oriented points (large-meshes paper §3.1's
// truncated signed distance): at a corner c, the weighted mean of the points' plane distances
// n·(c − p) over the points within `radius`, weights (1 − |c − p|²/r²)². No value (NaN) where
// fewer than `minPoints` points are that near: no surface bridges a hole.
//
// §3.3 makes the values of overlapping chunks identical by averaging them; here they are
// identical by construction: a corner's value depends only on the point cells within the
// radius, every chunk holds all of their points (its overlap is at least the radius, in whole
// cells), sums each cell in input order and spreads the cells in one global order, so two
// chunks compute the same bits. No value either past the edge of the points
// (DistanceOptions::edge).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <unordered_map>
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

// The sums behind a box's corner values, filled a point at a time (a chunk's points can be
// streamed through it from a file). A point is first summed into its half-voxel point cell
// (pointCellOf): count, Σ(p − o), Σn and Σ n·(p − o) from the cell's corner o, in input order;
// values() then spreads each cell to the corners within the radius of its centroid, the cells in
// global order, split by rows of corners between the threads. The plane distances are exact sums
// (Σ n·(c − p) = Σn·(c − o) − Σ n·(p − o)); only the weight is taken at the centroid, a quarter
// voxel from any point at most, where a dense cloud would spread every point on its own. A cell
// summed in any box that holds all its points is the same bits, and so is every corner value.
class CornerSums {
 public:
  CornerSums(const VoxelGrid& grid, const DistanceOptions& options,
             std::array<std::uint64_t, 3> first, std::array<std::uint32_t, 3> size);
  // Adds a point (in input order: the order of every sum).
  void add(Vec3d at, Vec3f normal);
  // The values: NaN where fewer than minPoints points are near or past the edge of the points.
  // The rows of corners are shared between `threads` (0: the arena's; 1: this thread alone, as
  // when the chunks themselves are made in parallel); the same bits for any count.
  CornerValues values(int threads = 0) const;

 private:
  // One point cell's sums.
  struct Cell {
    Vec3d offset, normal;  // Σ (p − o), Σ n
    double plane = 0;      // Σ n·(p − o)
    std::uint32_t count = 0;
  };
  // One corner's sums side by side: a cell's update touches one cache line per corner.
  struct Sums {
    double weight = 0, sum = 0;
    Vec3f offset, direction;  // Σ w (p − c), Σ w n (only compared)
    std::uint32_t near = 0;
  };
  struct CellHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
      const auto x = static_cast<std::uint64_t>(c[0]), y = static_cast<std::uint64_t>(c[1]),
                 z = static_cast<std::uint64_t>(c[2]);
      return static_cast<std::size_t>((x * 0x9E3779B97F4A7C15ull) ^ (y * 0xC2B2AE3D27D4EB4Full) ^
                                      (z * 0x165667B19E3779F9ull));
    }
  };
  // Where a cell's points are on average: where its weights are taken.
  Vec3d centroidOf(const std::array<std::int64_t, 3>& key, const Cell& cell) const;
  // Spreads a cell to the box's corners within the radius of its centroid whose row (y index in
  // the box) is in [rowFirst, rowEnd).
  void spread(const std::array<std::int64_t, 3>& key, const Cell& cell, std::vector<Sums>& corners,
              std::uint32_t rowFirst, std::uint32_t rowEnd) const;

  const VoxelGrid& grid_;
  DistanceOptions options_;
  std::array<std::uint64_t, 3> first_;
  std::array<std::uint32_t, 3> size_;
  std::unordered_map<std::array<std::int64_t, 3>, Cell, CellHash> cells_;
};

// Fills values.values for the box values.first/size from the points (CornerSums in one go).
void signedDistances(const VoxelGrid& grid, const OrientedPoints& points,
                     const DistanceOptions& options, CornerValues& values);

}  // namespace lodforge
