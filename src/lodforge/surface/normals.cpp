#include "lodforge/surface/normals.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <queue>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Eigenvalues>

#include "lodforge/surface/point_index.h"

namespace lodforge {

namespace {

// The k nearest of every point (itself included), k per point. Asked in the tree's leaf order,
// where one query's data is mostly the last one's (the answers do not depend on the order).
std::vector<std::uint32_t> nearest(const PointIndex& tree, std::span<const Vec3d> points,
                                   std::size_t k) {
  std::vector<std::uint32_t> out(points.size() * k);
  const std::span<const std::uint32_t> order = tree.leafOrder();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size()), [&](const auto& range) {
    std::vector<double> d2(k);
    for (std::size_t at = range.begin(); at != range.end(); ++at) {
      const std::size_t i = order[at];
      const std::size_t found = tree.nearest(points[i], k, out.data() + i * k, d2.data());
      for (std::size_t f = found; f < k; ++f) out[i * k + f] = out[i * k];  // fewer than k
    }
  });
  return out;
}

Vec3f leastSpread(std::span<const Vec3d> points, std::span<const std::uint32_t> neighbours) {
  Vec3d mean;
  for (std::uint32_t n : neighbours) mean = mean + points[n];
  mean = mean * (1.0 / static_cast<double>(neighbours.size()));
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::uint32_t n : neighbours) {
    const Vec3d d = points[n] - mean;
    const Eigen::Vector3d e(d.x, d.y, d.z);
    covariance += e * e.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d n = solver.eigenvectors().col(0);  // eigenvalues ascend
  return normalizeOr(
      Vec3f{static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())},
      Vec3f{0, 0, 1});
}

// Prim's tree over the neighbour graph, cheapest where neighbouring normals are most parallel,
// each normal turned to agree with its parent's; a new tree from the highest point left, up.
void propagate(std::span<const Vec3d> points, std::span<const std::uint32_t> knn, std::size_t k,
               std::vector<Vec3f>& normals) {
  const std::size_t n = points.size();
  // The graph made symmetric: j near i or i near j.
  std::vector<std::vector<std::uint32_t>> adjacent(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t f = 0; f < k; ++f) {
      const std::uint32_t j = knn[i * k + f];
      if (j == i) continue;
      adjacent[i].push_back(j);
      adjacent[j].push_back(static_cast<std::uint32_t>(i));
    }
  std::vector<char> done(n, 0);
  std::vector<std::uint32_t> byHeight(n);
  for (std::uint32_t i = 0; i < n; ++i) byHeight[i] = i;
  std::sort(byHeight.begin(), byHeight.end(), [&](std::uint32_t a, std::uint32_t b) {
    return points[a].z != points[b].z ? points[a].z > points[b].z : a < b;
  });
  struct Step {
    float cost;
    std::uint32_t to, from;
    bool operator>(const Step& o) const {
      return cost != o.cost ? cost > o.cost : to != o.to ? to > o.to : from > o.from;
    }
  };
  std::priority_queue<Step, std::vector<Step>, std::greater<>> queue;
  const auto reach = [&](std::uint32_t i) {
    done[i] = 1;
    for (std::uint32_t j : adjacent[i])
      if (!done[j]) queue.push({1 - std::abs(dot(normals[i], normals[j])), j, i});
  };
  for (std::uint32_t seed : byHeight) {
    if (done[seed]) continue;
    if (normals[seed].z < 0) normals[seed] = normals[seed] * -1.0f;
    reach(seed);
    while (!queue.empty()) {
      const Step s = queue.top();
      queue.pop();
      if (done[s.to]) continue;
      if (dot(normals[s.to], normals[s.from]) < 0) normals[s.to] = normals[s.to] * -1.0f;
      reach(s.to);
    }
  }
}

}  // namespace

std::vector<Vec3f> estimateNormals(std::span<const Vec3d> positions, const PointIndex& tree,
                                   const NormalOptions& options) {
  assert(tree.leafOrder().size() == positions.size());
  std::vector<Vec3f> normals(positions.size(), Vec3f{0, 0, 1});
  if (positions.size() < 3) return normals;
  const std::size_t k = std::min<std::size_t>(
      positions.size(), static_cast<std::size_t>(std::max(3, options.neighbours)));
  const std::vector<std::uint32_t> knn = nearest(tree, positions, k);
  const std::span<const std::uint32_t> order = tree.leafOrder();
  tbb::parallel_for(std::size_t{0}, positions.size(), [&](std::size_t at) {
    const std::size_t i = order[at];
    normals[i] = leastSpread(positions, std::span<const std::uint32_t>(knn).subspan(i * k, k));
  });
  switch (options.orientation) {
    case NormalOrientation::kUp:
      for (Vec3f& n : normals)
        if (n.z < 0) n = n * -1.0f;
      break;
    case NormalOrientation::kViewpoint:
      for (std::size_t i = 0; i < normals.size(); ++i)
        if (dot(toDouble(normals[i]), options.viewpoint - positions[i]) < 0)
          normals[i] = normals[i] * -1.0f;
      break;
    case NormalOrientation::kPropagate:
      propagate(positions, knn, k, normals);
      break;
  }
  return normals;
}

double medianSpacing(std::span<const Vec3d> positions, const PointIndex& tree,
                     std::size_t samples) {
  assert(tree.leafOrder().size() == positions.size() && samples > 0);
  if (positions.size() < 2) return 0;
  const std::size_t step = std::max<std::size_t>(1, positions.size() / samples);
  std::vector<double> gaps;
  for (std::size_t i = 0; i < positions.size(); i += step) {
    // The nearest other point: the second of two (the first is the point or a duplicate).
    std::uint32_t index[8];
    double d2[8];
    const std::size_t found = tree.nearest(positions[i], 8, index, d2);
    for (std::size_t f = 0; f < found; ++f)
      if (d2[f] > 0) {
        gaps.push_back(std::sqrt(d2[f]));
        break;
      }
  }
  if (gaps.empty()) return 0;
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2),
                   gaps.end());
  return gaps[gaps.size() / 2];
}

}  // namespace lodforge
