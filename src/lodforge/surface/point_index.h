// Nearest-neighbour queries over positions in memory (a nanoflann k-d tree).
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "lodforge/core/math.h"

namespace lodforge {

class PointIndex {
 public:
  explicit PointIndex(std::span<const Vec3d> points);  // kept alive by the caller
  PointIndex(PointIndex&&) noexcept;
  ~PointIndex();
  // The up to k nearest points to q, nearest first; how many were found.
  std::size_t nearest(Vec3d q, std::size_t k, std::uint32_t* indices, double* distances2) const;
  // Every point's index in the tree's leaf order: points near in space are near in it, so
  // queries made in this order find the tree's data in cache.
  std::span<const std::uint32_t> leafOrder() const;

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

}  // namespace lodforge
