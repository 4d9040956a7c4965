#include "lodforge/points/cluster.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include <tbb/parallel_for.h>
#include <Eigen/Eigenvalues>

namespace lodforge {

namespace {

// Node i's points are points[begin, end) once the tree is built (splitting reorders in place).
struct Range {
  std::uint32_t begin, end;
  std::uint32_t size() const { return end - begin; }
};

// How a node was split: its first child's points have coordinate `axis` ≤ value, the second's
// ≥ value. The clustering tree is a k-d tree, searched for nearest neighbours with these.
struct Separator {
  int axis = 0;
  double value = 0;
};

// What splitting reads of a point, half a CloudPoint's bytes: the splits move these, and the
// points and ids follow once at the end (each level of splits moves every point).
struct SplitItem {
  Vec3d position;
  Rgba8 color;
  std::uint32_t index;  // the point's place before splitting
};
static_assert(sizeof(SplitItem) == 32);

// `points` (and `ids`, if any) in the items' order.
void followItems(std::span<const SplitItem> items, std::span<CloudPoint> points,
                 std::span<std::uint32_t> ids) {
  std::vector<std::uint32_t> order(items.size());
  for (std::size_t k = 0; k < items.size(); ++k) order[k] = items[k].index;
  applyOrder(order, points);
  applyOrder(order, ids);
}

// The items' mean colour, rounded (§4.1's node colour).
Rgba8 meanColor(std::span<const SplitItem> items) {
  Vec3d color;
  for (const SplitItem& p : items)
    color = color + Vec3d{double(p.color.r), double(p.color.g), double(p.color.b)};
  color = color * (1 / static_cast<double>(items.size()));
  return {static_cast<std::uint8_t>(std::lround(color.x)),
          static_cast<std::uint8_t>(std::lround(color.y)),
          static_cast<std::uint8_t>(std::lround(color.z)), 255};
}

// A node's bounds and coordinate sum (summed in its items' order).
struct SplitStats {
  Aabbd bounds;
  Vec3d sum;
};

SplitStats statsOf(std::span<const SplitItem> items) {
  SplitStats stats;
  for (const SplitItem& p : items) {
    stats.bounds.add(p.position);
    stats.sum = stats.sum + p.position;
  }
  return stats;
}

// Moves `from` into `to` split by the plane (those below first, in their order; those above
// after, in reverse order); how many are below. Branch free (Hoare's partition mispredicted
// about every other point): each item is written to both free ends and one end advances.
std::size_t splitInto(std::span<const SplitItem> from, std::span<SplitItem> to, SplitPlane plane) {
  std::size_t low = 0, high = to.size();
  for (const SplitItem& item : from) {
    const bool below = item.position[plane.axis] < plane.value;
    to[low] = item;
    to[high - 1] = item;
    low += below ? 1 : 0;
    high -= below ? 0 : 1;
  }
  return low;
}

// Top-down splitting (§4.1, "Hierarchical clustering"), breadth-first: each node's centroid,
// mean colour and count; splitting node i reorders only inside ranges[i]. Each level's pass
// moves a node's items into the other of two buffers; a leaf's item goes back to the first
// buffer, where the points' order is read at the end.
void splitTree(std::span<CloudPoint> points, std::span<std::uint32_t> ids, Vec3d origin,
               bool colors, std::vector<ClusterNode>& nodes, std::vector<Range>& ranges,
               std::vector<Separator>& separators) {
  nodes.reserve(2 * points.size() - 1);
  ranges.reserve(2 * points.size() - 1);
  separators.resize(2 * points.size() - 1);
  std::vector<SplitItem> buffers[2] = {std::vector<SplitItem>(points.size()),
                                       std::vector<SplitItem>(points.size())};
  for (std::uint32_t k = 0; k < points.size(); ++k)
    buffers[0][k] = {points[k].position, points[k].color, k};
  std::vector<std::uint8_t> in{0};  // which buffer holds the node's items
  in.reserve(2 * points.size() - 1);
  nodes.emplace_back();
  ranges.push_back({0, static_cast<std::uint32_t>(points.size())});
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Range r = ranges[i];
    const int from = in[i];
    const std::span<SplitItem> mine = std::span(buffers[from]).subspan(r.begin, r.size());
    const SplitStats stats = statsOf(mine);
    const double n = static_cast<double>(mine.size());
    const Vec3d centroid = stats.sum * (1 / n);
    ClusterNode& node = nodes[i];
    node.position = toFloat(centroid - origin);
    if (colors) node.color = meanColor(mine);
    node.pointCount = static_cast<std::uint32_t>(mine.size());
    if (mine.size() == 1) {
      buffers[0][r.begin] = mine[0];
      continue;
    }
    const Aabbd bounds = stats.bounds;
    const SplitPlane plane = centroidSplit(bounds, centroid);
    const std::span<SplitItem> next = std::span(buffers[1 - from]).subspan(r.begin, r.size());
    std::size_t below = splitInto(mine, next, plane);
    // When the centroid leaves every point on one side, splitPoints splits at the median.
    const bool median = below == 0 || below == mine.size();
    if (median) {
      // With ids the split keeps a flat node's order, as splitPoints does.
      below = splitRecords(mine, plane, {}, !ids.empty());
      std::copy(mine.begin(), mine.end(), next.begin());
    }
    separators[i] = {plane.axis, median ? next[below].position[plane.axis] : plane.value};
    node.firstChild = static_cast<std::uint32_t>(nodes.size());
    const auto cut = static_cast<std::uint32_t>(below);
    for (std::size_t side = 0; side < 2; ++side) {
      nodes.emplace_back();
      ranges.push_back(side == 0 ? Range{r.begin, r.begin + cut} : Range{r.begin + cut, r.end});
      in.push_back(static_cast<std::uint8_t>(1 - from));
    }
  }
  followItems(buffers[0], points, ids);
}

// The direction of least spread of `points` (PCA), facing +z; +z for fewer than three points.
Vec3f pcaNormal(std::span<const CloudPoint> points) {
  if (points.size() < 3) return {0, 0, 1};
  Vec3d mean;
  for (const CloudPoint& p : points) mean = mean + p.position;
  mean = mean * (1.0 / static_cast<double>(points.size()));
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const CloudPoint& p : points) {
    const Vec3d d = p.position - mean;
    const Eigen::Vector3d e(d.x, d.y, d.z);
    covariance += e * e.transpose();
  }
  // Eigenvalues come in increasing order.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  Eigen::Vector3d normal = solver.eigenvectors().col(0);
  if (normal.z() < 0) normal = -normal;
  return normalizeOr(Vec3f{static_cast<float>(normal.x()), static_cast<float>(normal.y()),
                           static_cast<float>(normal.z())},
                     Vec3f{0, 0, 1});
}

// Each point's normal, when the input has none, by PCA over its cell: the smallest node of
// the tree holding at least k points (the splitting made every node's points contiguous, so
// no k-nearest-neighbour search is needed).
void cellNormals(std::span<CloudPoint> points, std::span<const ClusterNode> nodes,
                 std::span<const Range> ranges, std::uint32_t k) {
  const auto settle = [&](const Range& cell, const Range& own) {
    const Vec3f normal = pcaNormal(points.subspan(cell.begin, cell.size()));
    for (CloudPoint& p : points.subspan(own.begin, own.size())) p.normal = normal;
  };
  if (ranges[0].size() < k) return settle(ranges[0], ranges[0]);
  // Nodes with at least k points hand their small children (fewer than k) their plane.
  tbb::parallel_for(std::size_t{0}, nodes.size(), [&](std::size_t i) {
    if (ranges[i].size() < k || nodes[i].leaf()) return;
    const std::uint32_t a = nodes[i].firstChild, b = a + 1;
    if (ranges[a].size() < k && ranges[b].size() < k) return settle(ranges[i], ranges[i]);
    for (std::uint32_t c : {a, b})
      if (ranges[c].size() < k) settle(ranges[i], ranges[c]);
  });
}

// The least of `best` and the squared distances from `p` to positions[from, to). Not inlined:
// inside the search, whose loop makes calls, GCC kept `best` in memory (no vector register
// survives a call), a store and a load on every point of a bucket.
[[gnu::noinline]] double nearestSquared(std::span<const Vec3d> positions, std::uint32_t from,
                                        std::uint32_t to, Vec3d p, double best) {
  for (std::uint32_t q = from; q < to; ++q) {
    const Vec3d d = positions[q] - p;
    const double squared = dot(d, d);
    best = squared < best ? squared : best;
  }
  return best;
}

// Half the distance from every point to its nearest other point (0 for a lone point or a
// duplicate), by searching the clustering tree as the k-d tree it is: up from the point's
// leaf, into each sibling subtree only where its side of the separator is nearer than the
// best so far. Exact, and no second spatial index per block.
std::vector<float> halfSpacing(std::span<const Vec3d> positions, std::span<const ClusterNode> nodes,
                               std::span<const Range> ranges,
                               std::span<const Separator> separators) {
  std::vector<float> spacing(positions.size(), 0);
  if (positions.size() < 2) return spacing;
  // The tree packed for the search, depth first (a subtree's nodes close together; the tree's
  // own breadth-first order scatters them, and the search waited on memory), with subtrees of
  // at most kBucket points as buckets searched by brute force (fewer unpredictable branches):
  // a split's axis, value and first child (children stay adjacent), or a bucket's points.
  constexpr std::uint32_t kBucket = 16;
  struct KdNode {
    double value;
    std::uint32_t next;   // first child, or the bucket's first point
    std::uint32_t count;  // 0 for a split, else the bucket's points
    int axis;
  };
  std::vector<KdNode> kd(nodes.size());
  std::vector<std::uint32_t> parent(nodes.size(), 0), bucketOf(positions.size(), 0);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> order{{0, 0}};  // tree node, packed index
  std::uint32_t placed = 1;
  while (!order.empty()) {
    const auto [i, at] = order.back();
    order.pop_back();
    if (nodes[i].leaf() || ranges[i].size() <= kBucket) {
      kd[at] = {0, ranges[i].begin, ranges[i].size(), 0};
      for (std::uint32_t j = ranges[i].begin; j < ranges[i].end; ++j) bucketOf[j] = at;
      continue;
    }
    kd[at] = {separators[i].value, placed, 0, separators[i].axis};
    parent[placed] = parent[placed + 1] = at;
    order.emplace_back(nodes[i].firstChild + 1, placed + 1);
    order.emplace_back(nodes[i].firstChild, placed);
    placed += 2;
  }
  tbb::parallel_for(
      tbb::blocked_range<std::uint32_t>(0, static_cast<std::uint32_t>(positions.size()), 256),
      [&](const tbb::blocked_range<std::uint32_t>& range) {
        std::vector<std::pair<std::uint32_t, double>> stack;  // node, least distance² to it
        for (std::uint32_t j = range.begin(); j < range.end(); ++j) {
          const Vec3d p = positions[j];
          const auto bucket = [&](const KdNode& n, double best) {
            const std::uint32_t end = n.next + n.count;
            if (j < n.next || j >= end) return nearestSquared(positions, n.next, end, p, best);
            best = nearestSquared(positions, n.next, j, p, best);
            return nearestSquared(positions, j + 1, end, p, best);
          };
          double best = bucket(kd[bucketOf[j]], std::numeric_limits<double>::infinity());
          for (std::uint32_t node = bucketOf[j]; node != 0; node = parent[node]) {
            const KdNode& up = kd[parent[node]];
            const double gap = p[up.axis] - up.value;
            if (gap * gap >= best) continue;
            stack.assign(1, {node == up.next ? node + 1 : node - 1, gap * gap});
            while (!stack.empty()) {
              const auto [t, least] = stack.back();
              stack.pop_back();
              if (least >= best) continue;
              const KdNode& n = kd[t];
              if (n.count > 0) {
                best = bucket(n, best);
                continue;
              }
              const double side = p[n.axis] - n.value;
              // The far child first onto the stack: the near one is searched before it.
              stack.emplace_back(side < 0 ? n.next + 1 : n.next, side * side);
              stack.emplace_back(side < 0 ? n.next : n.next + 1, least);
            }
          }
          spacing[j] = static_cast<float>(std::sqrt(best) / 2);
        }
      });
  return spacing;
}

// Node normals bottom-up: the normalised sum of their points' normals (the paper's V); the
// sums, which the errors read.
std::vector<Vec3d> nodeNormals(std::span<const CloudPoint> points, std::span<ClusterNode> nodes,
                               std::span<const Range> ranges) {
  std::vector<Vec3d> sums(nodes.size());
  for (std::size_t i = nodes.size(); i-- > 0;) {
    ClusterNode& node = nodes[i];
    const Vec3f first = points[ranges[i].begin].normal;
    sums[i] = node.leaf() ? toDouble(first) : sums[node.firstChild] + sums[node.firstChild + 1];
    node.normal = toFloat(normalizeOr(sums[i], toDouble(first)));
  }
  return sums;
}

// Radii bottom-up: a leaf covers half the gap to its nearest neighbour, a parent covers its
// children's squares (in its own plane).
void nodeRadii(std::span<ClusterNode> nodes, std::span<const Range> ranges,
               std::span<const float> spacing) {
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
}

// Fitting error (§4.1, the paper's E with α1 = α2 = 0.5), then made monotone bottom-up.
// The turn, Σ (1 − n_k · n), is |node| − (Σ n_k) · n: the normals' sums make it one product.
void nodeErrors(std::span<const Vec3d> positions, Vec3d origin, std::span<ClusterNode> nodes,
                std::span<const Range> ranges, std::span<const Vec3d> normalSums,
                const ClusterOptions& options) {
  tbb::parallel_for(std::size_t{0}, nodes.size(), [&](std::size_t i) {
    ClusterNode& node = nodes[i];
    if (node.leaf()) return;
    const Vec3d c = origin + toDouble(node.position);
    const Vec3d normal = toDouble(node.normal);
    double distance = 0;
    for (std::uint32_t k = ranges[i].begin; k < ranges[i].end; ++k)
      distance += std::abs(dot(positions[k] - c, normal));
    const double n = static_cast<double>(ranges[i].size());
    const double turn = std::max(0.0, n - dot(normalSums[i], normal));  // no rounding below 0
    node.error =
        static_cast<float>(options.alpha1 * distance / n + options.alpha2 * node.radius * turn / n);
  });
  for (std::size_t i = nodes.size(); i-- > 0;) {
    ClusterNode& node = nodes[i];
    if (!node.leaf())
      node.error =
          std::max({node.error, nodes[node.firstChild].error, nodes[node.firstChild + 1].error});
  }
}

}  // namespace

std::vector<ClusterNode> clusterBlock(std::span<CloudPoint> points, Vec3d origin, bool hasNormals,
                                      const ClusterOptions& options,
                                      std::vector<std::uint32_t>* firstPoint,
                                      std::span<std::uint32_t> ids) {
  std::vector<ClusterNode> nodes;
  if (points.empty()) return nodes;
  std::vector<Range> ranges;
  std::vector<Separator> separators;
  splitTree(points, ids, origin, options.colors, nodes, ranges, separators);
  if (!hasNormals)
    cellNormals(points, nodes, ranges, static_cast<std::uint32_t>(std::max(3, options.neighbours)));
  // The positions alone, packed: the search and the errors read nothing else of a point.
  std::vector<Vec3d> positions(points.size());
  for (std::size_t j = 0; j < points.size(); ++j) positions[j] = points[j].position;
  const std::vector<float> spacing = halfSpacing(positions, nodes, ranges, separators);
  const std::vector<Vec3d> normalSums = nodeNormals(points, nodes, ranges);
  nodeRadii(nodes, ranges, spacing);
  nodeErrors(positions, origin, nodes, ranges, normalSums, options);
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
