#include "lodforge/surface/point_index.h"

#include <cassert>

#include <nanoflann.hpp>

namespace lodforge {

namespace {
struct Cloud {
  std::span<const Vec3d> points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  double kdtree_get_pt(std::size_t i, std::size_t axis) const {
    return points[i][static_cast<int>(axis)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
}  // namespace

struct PointIndex::Tree {
  Cloud cloud;
  nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3,
                                      std::uint32_t>
      index;
  explicit Tree(std::span<const Vec3d> points)
      : cloud{points}, index(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    index.buildIndex();
  }
};

PointIndex::PointIndex(std::span<const Vec3d> points) : tree_(std::make_unique<Tree>(points)) {}
PointIndex::PointIndex(PointIndex&&) noexcept = default;
PointIndex::~PointIndex() = default;

std::size_t PointIndex::nearest(Vec3d q, std::size_t k, std::uint32_t* indices,
                                double* distances2) const {
  assert(indices != nullptr && distances2 != nullptr);
  const double at[3] = {q.x, q.y, q.z};
  return tree_->index.knnSearch(at, k, indices, distances2);
}

std::span<const std::uint32_t> PointIndex::leafOrder() const {
  return tree_->index.vAcc;
}

}  // namespace lodforge
