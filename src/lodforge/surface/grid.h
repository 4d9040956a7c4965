// The reconstruction's voxel grid (large-meshes paper §3.1): one global lattice of corners
// `voxel` apart from `origin`, cut into chunks of N voxels along an edge. Every value lives at a
// global corner, so a corner shared by two chunks is one and the same corner of both.
#pragma once

#include <array>
#include <cassert>
#include <cstdint>
#include <vector>

#include "lodforge/core/math.h"

namespace lodforge {

// floor and ceil to an integer without a call into libm (the per-point loops run them by the
// hundred million); exact for |x| < 2⁶³.
inline std::int64_t floorToInt(double x) {
  const auto t = static_cast<std::int64_t>(x);
  return static_cast<double>(t) > x ? t - 1 : t;
}
inline std::int64_t ceilToInt(double x) {
  const auto t = static_cast<std::int64_t>(x);
  return static_cast<double>(t) < x ? t + 1 : t;
}

struct VoxelGrid {
  Vec3d origin;  // world position of global corner (0, 0, 0)
  double voxel = 1;
  std::array<std::uint64_t, 3> corners{};  // global corners along each axis

  Vec3d position(std::uint64_t i, std::uint64_t j, std::uint64_t k) const {
    return origin +
           Vec3d{static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)} * voxel;
  }
};

// Points are summed per half-voxel cell before they are spread to the corners (implicit.h): the
// cell holding p, in global half-voxel coordinates.
inline constexpr int kCellSplit = 2;
inline std::array<std::int64_t, 3> pointCellOf(const VoxelGrid& grid, const Vec3d& p) {
  const double scale = kCellSplit / grid.voxel;
  return {floorToInt((p.x - grid.origin.x) * scale), floorToInt((p.y - grid.origin.y) * scale),
          floorToInt((p.z - grid.origin.z) * scale)};
}

// The values of a box of global corners [first, first + size) (x fastest), NaN where no point
// is near enough to say.
struct CornerValues {
  std::array<std::uint64_t, 3> first{};
  std::array<std::uint32_t, 3> size{};
  std::vector<float> values;

  std::size_t index(std::uint32_t i, std::uint32_t j, std::uint32_t k) const {
    assert(i < size[0] && j < size[1] && k < size[2]);
    return (static_cast<std::size_t>(k) * size[1] + j) * size[0] + i;
  }
};

}  // namespace lodforge
