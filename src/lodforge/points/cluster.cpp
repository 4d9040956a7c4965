#include "lodforge/points/cluster.h"

#include <algorithm>
#include <cmath>
#include <deque>

#include <tbb/parallel_for.h>
#include <Eigen/Eigenvalues>
#include <nanoflann.hpp>

namespace lodforge {

namespace {

// Positions relative to a local origin, in float, for nanoflann.
struct LocalPoints {
  std::vector<Vec3f> positions;
  std::size_t kdtree_get_point_count() const { return positions.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t axis) const {
    return axis == 0 ? positions[i].x : axis == 1 ? positions[i].y : positions[i].z;
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, LocalPoints>,
                                                   LocalPoints, 3, std::uint32_t>;

LocalPoints localPoints(std::span<const CloudPoint> points) {
  LocalPoints local;
  local.positions.resize(points.size());
  const Vec3d origin = points.empty() ? Vec3d{} : points[0].position;
  for (std::size_t i = 0; i < points.size(); ++i)
    local.positions[i] = toFloat(points[i].position - origin);
  return local;
}

// Half the distance from every point to its nearest other point (0 for a lone point).
std::vector<float> halfSpacing(std::span<const CloudPoint> points) {
  std::vector<float> spacing(points.size(), 0);
  if (points.size() < 2) return spacing;
  const LocalPoints local = localPoints(points);
  KdTree tree(3, local, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  tree.buildIndex();
  tbb::parallel_for(std::size_t{0}, points.size(), [&](std::size_t i) {
    std::uint32_t found[2];
    float squared[2];
    const std::size_t n = tree.knnSearch(&local.positions[i].x, 2, found, squared);
    // The nearest is usually the point itself; a duplicate has distance 0 either way.
    float nearest = 0;
    for (std::size_t k = 0; k < n; ++k)
      if (found[k] != i) nearest = std::sqrt(squared[k]);
    spacing[i] = nearest / 2;
  });
  return spacing;
}

}  // namespace

void estimateNormals(std::span<CloudPoint> points, int neighbours) {
  if (points.size() < 3) {
    for (CloudPoint& p : points) p.normal = {0, 0, 1};
    return;
  }
  const LocalPoints local = localPoints(points);
  KdTree tree(3, local, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  tree.buildIndex();
  const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(neighbours), points.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::vector<std::uint32_t> found(k);
                      std::vector<float> squared(k);
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        const std::size_t n =
                            tree.knnSearch(&local.positions[i].x, k, found.data(), squared.data());
                        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
                        for (std::size_t j = 0; j < n; ++j) {
                          const Vec3f& q = local.positions[found[j]];
                          mean += Eigen::Vector3d(q.x, q.y, q.z);
                        }
                        mean /= static_cast<double>(n);
                        Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
                        for (std::size_t j = 0; j < n; ++j) {
                          const Vec3f& q = local.positions[found[j]];
                          const Eigen::Vector3d d = Eigen::Vector3d(q.x, q.y, q.z) - mean;
                          covariance += d * d.transpose();
                        }
                        // The direction of least spread (eigenvalues come in increasing order).
                        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
                        Eigen::Vector3d normal = solver.eigenvectors().col(0);
                        if (normal.z() < 0) normal = -normal;
                        points[i].normal = normalizeOr(
                            Vec3f{static_cast<float>(normal.x()), static_cast<float>(normal.y()),
                                  static_cast<float>(normal.z())},
                            Vec3f{0, 0, 1});
                      }
                    });
}

std::vector<ClusterNode> clusterBlock(std::span<CloudPoint> points, Vec3d origin, bool hasNormals,
                                      const ClusterOptions& options,
                                      std::vector<std::uint32_t>* firstPoint) {
  std::vector<ClusterNode> nodes;
  if (points.empty()) return nodes;
  if (!hasNormals) estimateNormals(points, options.neighbours);
  // Top-down splitting (§4.1, "Hierarchical clustering"), breadth-first: node i's points are the
  // range ranges[i], and splitting it reorders only inside that range.
  struct Range {
    std::uint32_t begin, end;
  };
  std::vector<Range> ranges;
  nodes.reserve(2 * points.size() - 1);
  ranges.reserve(2 * points.size() - 1);
  nodes.emplace_back();
  ranges.push_back({0, static_cast<std::uint32_t>(points.size())});
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Range r = ranges[i];
    const std::span<CloudPoint> mine = points.subspan(r.begin, r.end - r.begin);
    Aabbd bounds;
    Vec3d sum, color;
    Vec3d normalSum;
    for (const CloudPoint& p : mine) {
      bounds.add(p.position);
      sum = sum + p.position;
      normalSum = normalSum + toDouble(p.normal);
      color = color + Vec3d{double(p.color.r), double(p.color.g), double(p.color.b)};
    }
    const double n = static_cast<double>(mine.size());
    const Vec3d centroid = sum * (1 / n);
    ClusterNode& node = nodes[i];
    node.position = toFloat(centroid - origin);
    node.normal = toFloat(normalizeOr(normalSum, toDouble(mine[0].normal)));
    color = color * (1 / n);
    node.color = {static_cast<std::uint8_t>(std::lround(color.x)),
                  static_cast<std::uint8_t>(std::lround(color.y)),
                  static_cast<std::uint8_t>(std::lround(color.z)), 255};
    node.pointCount = static_cast<std::uint32_t>(mine.size());
    if (mine.size() == 1) continue;
    const std::size_t below = splitPoints(mine, centroidSplit(bounds, centroid));
    node.firstChild = static_cast<std::uint32_t>(nodes.size());
    nodes.emplace_back();
    nodes.emplace_back();
    ranges.push_back({r.begin, r.begin + static_cast<std::uint32_t>(below)});
    ranges.push_back({r.begin + static_cast<std::uint32_t>(below), r.end});
  }
  // Radii bottom-up: a leaf covers half the gap to its nearest neighbour, a parent covers its
  // children's squares (in its own plane).
  const std::vector<float> spacing = halfSpacing(points);
  for (std::size_t i = nodes.size(); i-- > 0;) {
    ClusterNode& node = nodes[i];
    if (node.leaf()) {
      node.radius = spacing[ranges[i].begin];
      continue;
    }
    float radius = 0;
    for (std::uint32_t c = node.firstChild; c < node.firstChild + 2; ++c) {
      const Vec3f d = nodes[c].position - node.position;
      const Vec3f inPlane = d - node.normal * dot(d, node.normal);
      radius = std::max(radius, length(inPlane) + nodes[c].radius);
    }
    node.radius = radius;
  }
  // Fitting error (§4.1, the paper's E with α1 = α2 = 0.5), then made monotone bottom-up.
  tbb::parallel_for(std::size_t{0}, nodes.size(), [&](std::size_t i) {
    ClusterNode& node = nodes[i];
    if (node.leaf()) return;
    const Vec3d c = origin + toDouble(node.position);
    const Vec3d normal = toDouble(node.normal);
    double distance = 0, turn = 0;
    for (std::uint32_t k = ranges[i].begin; k < ranges[i].end; ++k) {
      distance += std::abs(dot(points[k].position - c, normal));
      turn += 1 - dot(toDouble(points[k].normal), normal);
    }
    const double n = static_cast<double>(ranges[i].end - ranges[i].begin);
    node.error =
        static_cast<float>(options.alpha1 * distance / n + options.alpha2 * node.radius * turn / n);
  });
  for (std::size_t i = nodes.size(); i-- > 0;) {
    ClusterNode& node = nodes[i];
    if (!node.leaf())
      node.error =
          std::max({node.error, nodes[node.firstChild].error, nodes[node.firstChild + 1].error});
  }
  if (firstPoint) {
    firstPoint->resize(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) (*firstPoint)[i] = ranges[i].begin;
  }
  return nodes;
}

LodCut cutTree(std::span<const ClusterNode> tree, float tolerance) {
  LodCut cut;
  if (tree.empty()) return cut;
  // Part I and Part II: down from the root until the error is within the tolerance.
  std::vector<std::uint32_t> residentIndex;
  std::deque<std::uint32_t> queue{0};
  while (!queue.empty()) {
    const std::uint32_t t = queue.front();
    queue.pop_front();
    if (tree[t].error <= tolerance || tree[t].leaf()) {
      residentIndex.push_back(t);
      cut.resident.push_back(tree[t]);
    } else {
      ++cut.dropped;
      queue.push_back(tree[t].firstChild);
      queue.push_back(tree[t].firstChild + 1);
    }
  }
  // Part III: their descendants breadth-first, each pair of children appended together.
  const auto expand = [&](std::uint32_t t) -> std::uint32_t {
    if (tree[t].leaf()) return ClusterNode::kNoChild;
    const auto first = static_cast<std::uint32_t>(cut.segment.size());
    cut.segment.push_back(tree[tree[t].firstChild]);
    cut.segment.push_back(tree[tree[t].firstChild + 1]);
    return first;
  };
  std::deque<std::pair<std::uint32_t, std::uint32_t>> order;  // (segment index, tree node)
  for (std::size_t j = 0; j < residentIndex.size(); ++j) {
    const std::uint32_t t = residentIndex[j];
    cut.resident[j].firstChild = expand(t);
    if (cut.resident[j].firstChild != ClusterNode::kNoChild) {
      order.emplace_back(cut.resident[j].firstChild, tree[t].firstChild);
      order.emplace_back(cut.resident[j].firstChild + 1, tree[t].firstChild + 1);
    }
  }
  while (!order.empty()) {
    const auto [s, t] = order.front();
    order.pop_front();
    const std::uint32_t first = expand(t);
    cut.segment[s].firstChild = first;
    if (first != ClusterNode::kNoChild) {
      order.emplace_back(first, tree[t].firstChild);
      order.emplace_back(first + 1, tree[t].firstChild + 1);
    }
  }
  return cut;
}

float toleranceForResident(std::span<const ClusterNode> tree, std::size_t residentNodes) {
  std::vector<float> errors;
  errors.reserve(tree.size());
  for (const ClusterNode& n : tree) errors.push_back(n.error);
  std::sort(errors.begin(), errors.end());
  errors.erase(std::unique(errors.begin(), errors.end()), errors.end());
  // Part II shrinks as the tolerance grows: the first error value whose cut is small enough.
  const auto residentAt = [&](float tolerance) {
    std::size_t count = 0;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      if (tree[t].error <= tolerance || tree[t].leaf()) {
        ++count;
      } else {
        stack.push_back(tree[t].firstChild);
        stack.push_back(tree[t].firstChild + 1);
      }
    }
    return count;
  };
  std::size_t lo = 0, hi = errors.size() - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (residentAt(errors[mid]) <= residentNodes) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return errors[lo];
}

}  // namespace lodforge
