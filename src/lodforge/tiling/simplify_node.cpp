#include "lodforge/tiling/simplify_node.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <utility>

#include <nanoflann.hpp>

#include "lodforge/core/distance.h"
#include "lodforge/core/mesh.h"
#include "lodforge/simplify/progressive.h"
#include "lodforge/simplify/simplify_model.h"
#include "lodforge/tiling/weld.h"

namespace lodforge {
namespace {

constexpr std::uint32_t kNoVertex = ~0u;

// Float positions relative to `center`: what the simplifier and the distance kernel take.
std::vector<Vec3f> relativeTo(const MeshPart& mesh, Vec3d center) {
  std::vector<Vec3f> out(mesh.positions.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = toFloat(mesh.positions[i] - center);
  return out;
}

// A sampling seed per node, so errors are reproducible.
std::uint64_t seedOf(const OctreeNode& node) {
  std::uint64_t seed = static_cast<std::uint64_t>(node.level) + 1;
  for (std::int32_t c : node.cell) seed = seed * 1'000'003 + static_cast<std::uint32_t>(c);
  return seed;
}

// The kept vertices for nanoflann's k-d tree.
struct KeptVertices {
  const std::vector<Vec3f>& points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t axis) const {
    return axis == 0 ? points[i].x : axis == 1 ? points[i].y : points[i].z;
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, KeptVertices>,
                                        KeptVertices, 3, std::uint32_t>;

// Flags the vertices on the outer faces of a node's cell: the planes of the leaf grid at its
// cell's ends (a level-L cell spans 2^L leaf cells per axis), compared exactly, as cuts set them.
std::vector<std::uint8_t> onOuterFaces(const MeshPart& mesh, const ChunkGrid& grid,
                                       const OctreeNode& node) {
  // Faces on the grid's own ends have no neighbour beyond them: NaN matches nothing.
  std::array<double, 6> planes{};
  for (int axis = 0; axis < 3; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    const std::int32_t first = node.cell[a] * (1 << node.level);
    const std::int32_t last = first + (1 << node.level);
    planes[2 * a] = first > 0 ? grid.plane(axis, first) : std::nan("");
    planes[2 * a + 1] = last < grid.dims[a] ? grid.plane(axis, last) : std::nan("");
  }
  std::vector<std::uint8_t> flags(mesh.positions.size(), 0);
  for (std::size_t v = 0; v < flags.size(); ++v) {
    const Vec3d& p = mesh.positions[v];
    for (int axis = 0; axis < 3; ++axis) {
      const auto a = static_cast<std::size_t>(axis);
      if (p[axis] == planes[2 * a] || p[axis] == planes[2 * a + 1]) flags[v] = 1;
    }
  }
  return flags;
}

// A bound on how far any input vertex is from the simplified surface, mostly without a search:
// each is at most its distance to the triangles around the vertex it was collapsed into (a part
// of that surface). A vertex whose whole piece collapsed away (an island's last triangle went)
// has no such fan: its distance to the whole surface is searched. Every vertex of `inputIndices`
// is covered, where area samples could miss a rim, a spike or a small island.
double removedVertexBound(std::span<const Vec3f> input, std::span<const std::uint32_t> inputIndices,
                          std::span<const Vec3f> positions, std::span<const std::uint32_t> indices,
                          const SimplifiedMesh& simplified) {
  // Triangles around each kept vertex (offsets into `fans`).
  std::vector<std::uint32_t> start(positions.size() + 1, 0), fans(indices.size());
  for (std::uint32_t v : indices) ++start[v + 1];
  for (std::size_t v = 0; v < positions.size(); ++v) start[v + 1] += start[v];
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < indices.size(); ++i)
    fans[fill[indices[i]]++] = static_cast<std::uint32_t>(i / 3);
  std::vector<std::uint8_t> used(input.size(), 0);
  for (std::uint32_t v : inputIndices) used[v] = 1;
  std::vector<Vec3f> vanished;
  double worst = 0;
  for (std::size_t v = 0; v < input.size(); ++v) {
    const std::uint32_t r = simplified.representative[v];
    if (r == ~0u) {
      if (used[v] != 0) vanished.push_back(input[v]);
      continue;
    }
    if (simplified.vertices[r] == v) continue;  // kept
    double best = std::numeric_limits<double>::max();
    for (std::uint32_t i = start[r]; i < start[r + 1] && best > worst; ++i) {
      // (A vertex already within `worst` of the fan cannot raise it: its search ends there.)
      const std::size_t t = 3 * std::size_t{fans[i]};
      best = std::min(
          best, pointTriangleDistanceSquared(toDouble(input[v]), toDouble(positions[indices[t]]),
                                             toDouble(positions[indices[t + 1]]),
                                             toDouble(positions[indices[t + 2]])));
    }
    if (best < std::numeric_limits<double>::max()) worst = std::max(worst, best);
  }
  const double bound = std::sqrt(worst);
  if (vanished.empty()) return bound;
  return std::max(bound, farthestDistance(vanished, positions, indices));
}

// Appends vertex `v` of `from` (every per-vertex array it has) to `to`.
void appendVertex(const MeshPart& from, std::uint32_t v, MeshPart& to) {
  to.positions.push_back(from.positions[v]);
  if (!from.colors.empty()) to.colors.push_back(from.colors[v]);
  if (!from.normals.empty()) to.normals.push_back(from.normals[v]);
  if (!from.features.empty()) to.features.push_back(from.features[v]);
  if (!from.uvs.empty()) {
    to.uvs.push_back(from.uvs[v]);
    to.materials.push_back(from.materials[v]);
  }
}

// Per vertex, the first vertex at its position: the two vertices of a UV seam (welding keeps
// them apart) are one point of the surface. Empty for an untextured mesh (every vertex its own).
std::vector<std::uint32_t> positionRepresentatives(const MeshPart& mesh) {
  if (mesh.uvs.empty()) return {};
  std::vector<std::uint32_t> order(mesh.vertexCount());
  for (std::uint32_t v = 0; v < order.size(); ++v) order[v] = v;
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const Vec3d &p = mesh.positions[a], &q = mesh.positions[b];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    return p.z != q.z ? p.z < q.z : a < b;
  });
  std::vector<std::uint32_t> first(mesh.vertexCount());
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i + 1;
    while (j < order.size() && mesh.positions[order[j]] == mesh.positions[order[i]]) ++j;
    for (std::size_t k = i; k < j; ++k) first[order[k]] = order[i];
    i = j;
  }
  return first;
}

struct Dropped {
  std::uint64_t segments = 0;
  double error = 0;  // bound on the distance from any dropped point to what remains
};

// Whole segments too small to matter at this level: a CAD part that cannot simplify further (a
// closed tube at the normal limit, a sheet's corners) would otherwise keep every parent above
// its target. When the simplified mesh is over its target, its connected components with no
// vertex on the node's outer faces (`shared`) — so no neighbouring tile meets them — go,
// smallest first, until the target is met or one component is left. `border` (a flag per
// vertex) is compacted with the mesh.
Dropped dropSmallSegments(MeshPart& mesh, std::vector<std::uint8_t>& border,
                          std::span<const std::uint8_t> shared, std::uint64_t target,
                          Vec3d center) {
  if (mesh.triangleCount() <= target) return {};
  // Components of the surface, not of its charts: joined across UV seams.
  const std::vector<std::uint32_t> samePosition = positionRepresentatives(mesh);
  std::vector<std::uint32_t> joined(mesh.indices);
  if (!samePosition.empty())
    for (std::uint32_t& v : joined) v = samePosition[v];
  std::vector<std::uint32_t> component(mesh.triangleCount());
  const std::uint32_t count = connectedComponents(mesh.vertexCount(), joined, component);
  if (count < 2) return {};
  std::vector<Aabbd> bounds(count);
  std::vector<std::uint64_t> triangles(count, 0);
  std::vector<std::uint8_t> touchesPlane(count, 0);
  for (std::size_t i = 0; i < mesh.indices.size(); ++i) {
    const std::uint32_t c = component[i / 3];
    const Vec3d& p = mesh.positions[mesh.indices[i]];
    bounds[c].add(p);
    if (shared[mesh.indices[i]] != 0) touchesPlane[c] = 1;
    if (i % 3 == 0) ++triangles[c];
  }
  std::vector<std::uint32_t> order;
  for (std::uint32_t c = 0; c < count; ++c)
    if (touchesPlane[c] == 0) order.push_back(c);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return length(bounds[a].size()) < length(bounds[b].size());
  });
  std::vector<std::uint8_t> drop(count, 0);
  Dropped dropped;
  std::uint64_t remaining = mesh.triangleCount();
  for (std::uint32_t c : order) {
    if (remaining <= target || dropped.segments + 1 == count) break;
    drop[c] = 1;
    remaining -= triangles[c];
    ++dropped.segments;
  }
  if (dropped.segments == 0) return {};

  // Keep the rest.
  std::vector<std::uint32_t> remap(mesh.vertexCount(), ~0u);
  std::vector<std::uint32_t> representative(count, ~0u);  // a vertex of each dropped component
  MeshPart kept;
  std::vector<std::uint8_t> keptBorder;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const std::uint32_t c = component[t / 3];
    if (drop[c] != 0) {
      representative[c] = mesh.indices[t];
      continue;
    }
    for (std::size_t k = 0; k < 3; ++k) {
      std::uint32_t& to = remap[mesh.indices[t + k]];
      if (to == ~0u) {
        to = kept.vertexCount();
        appendVertex(mesh, mesh.indices[t + k], kept);
        keptBorder.push_back(border[mesh.indices[t + k]]);
      }
      kept.indices.push_back(to);
    }
  }
  // The cost, bounded without searching far from the surface: every point of a dropped
  // component is within its bounds' diagonal of its representative vertex, which is within the
  // distance to the nearest kept vertex (a point of what remains) of the kept surface.
  const std::vector<Vec3f> keptPositions = relativeTo(kept, center);
  const KeptVertices cloud{keptPositions};
  const KdTree tree(3, cloud);
  for (std::uint32_t c = 0; c < count; ++c) {
    if (drop[c] == 0) continue;
    const Vec3f p = toFloat(mesh.positions[representative[c]] - center);
    const float query[3] = {p.x, p.y, p.z};
    std::uint32_t nearest = 0;
    float squared = 0;
    tree.knnSearch(query, 1, &nearest, &squared);
    dropped.error =
        std::max(dropped.error, std::sqrt(static_cast<double>(squared)) + length(bounds[c].size()));
  }
  mesh = std::move(kept);
  border = std::move(keptBorder);
  return dropped;
}

// One level's mesh as the simplifier left it: each vertex's source in the merged mesh, whether
// it sits on a boundary, the recorded error and the removed vertices' bound.
struct Collapsed {
  MeshPart mesh;
  std::vector<std::uint32_t> source;
  std::vector<std::uint8_t> border;
  double recorded = 0, vertexError = 0;
};

Collapsed simplifyPlain(const MeshPart& merged, std::span<const Vec3f> positions,
                        const ProgressiveOptions& simplify, Vec3d center) {
  SimplifiedMesh simplified = simplifyMesh(positions, merged.indices, simplify);
  Collapsed out;
  for (std::uint32_t v : simplified.vertices) appendVertex(merged, v, out.mesh);
  out.mesh.indices = simplified.indices;
  out.source = simplified.vertices;
  out.border = std::move(simplified.border);
  out.recorded = simplified.error;
  out.vertexError = removedVertexBound(positions, merged.indices, relativeTo(out.mesh, center),
                                       out.mesh.indices, simplified);
  return out;
}

// A textured mesh goes to the simplifier as its surface: one vertex per point (the two sides of a
// UV seam, which welding keeps apart, are one), each corner naming its wedge (the merged vertex
// it came from), so seams slide along themselves with both sides together (ProgressiveOptions::
// wedges) instead of being locked. Triangles with two corners at one point have no area; they go.
Collapsed simplifyTextured(const MeshPart& merged, std::span<const Vec3f> positions,
                           std::span<const std::uint32_t> samePosition,
                           std::span<const std::uint8_t> outer, ProgressiveOptions simplify) {
  std::vector<std::uint32_t> surfaceOf(merged.vertexCount(), kNoVertex), first;
  for (std::uint32_t v = 0; v < merged.vertexCount(); ++v) {
    if (samePosition[v] != v) continue;
    surfaceOf[v] = static_cast<std::uint32_t>(first.size());
    first.push_back(v);
  }
  std::vector<Vec3f> surfacePositions(first.size());
  std::vector<std::uint8_t> locked(first.size());
  for (std::size_t s = 0; s < first.size(); ++s) {
    surfacePositions[s] = positions[first[s]];
    locked[s] = outer[first[s]];
  }
  std::vector<std::uint32_t> pointOf(merged.vertexCount());
  for (std::uint32_t v = 0; v < merged.vertexCount(); ++v) pointOf[v] = surfaceOf[samePosition[v]];
  const WedgeSurface surface = wedgeSurface(pointOf, merged.indices);
  const std::vector<std::uint32_t>& indices = surface.indices;
  simplify.locked = locked;
  simplify.wedges = surface.wedges;
  simplify.wedgeUvs = merged.uvs;
  const SimplifiedMesh simplified = simplifyMesh(surfacePositions, indices, simplify);
  // The mesh again: one vertex per wedge still in use, in order of first use.
  Collapsed out;
  std::vector<std::uint32_t> remap(merged.vertexCount(), kNoVertex);
  std::vector<std::uint8_t> flagged = simplified.border;
  for (std::size_t i = 0; i < simplified.wedges.size(); ++i) {
    const std::uint32_t w = simplified.wedges[i];
    if (remap[w] == kNoVertex) {
      remap[w] = out.mesh.vertexCount();
      appendVertex(merged, w, out.mesh);
      out.source.push_back(w);
      // A point's border flag once, on its first wedge: the count is of points.
      const std::uint32_t point = simplified.indices[i];
      out.border.push_back(std::exchange(flagged[point], 0));
    }
    out.mesh.indices.push_back(remap[w]);
  }
  out.recorded = simplified.error;
  std::vector<Vec3f> kept(simplified.vertices.size());
  for (std::size_t i = 0; i < kept.size(); ++i) kept[i] = surfacePositions[simplified.vertices[i]];
  out.vertexError =
      removedVertexBound(surfacePositions, indices, kept, simplified.indices, simplified);
  return out;
}

}  // namespace

Aabbd boundsOf(const MeshPart& mesh) {
  Aabbd box;
  for (const Vec3d& p : mesh.positions) box.add(p);
  return box;
}

SimplifiedNode simplifyNode(std::vector<MeshPart> children, const ChunkGrid& grid,
                            const OctreeNode& node, const OctreeOptions& options) {
  // Weld the children along their shared borders: the cut vertices are bit-identical.
  MeshPart merged = concatenate(children);
  children.clear();
  weldExact(merged);
  const Vec3d center = node.bounds.center();
  const std::vector<Vec3f> positions = relativeTo(merged, center);
  ProgressiveOptions simplify;
  simplify.minNormalCos = std::cos(options.maxNormalDeviationDegrees * std::numbers::pi / 180);
  simplify.stopAtTriangles = static_cast<std::uint32_t>(std::max<double>(
      1, std::floor(options.reduction * static_cast<double>(merged.triangleCount()))));
  // Only the node's outer faces are shared with other tiles: vertices there never move. The
  // input's own rims (and seams inside the node) may simplify, along themselves.
  const std::vector<std::uint8_t> outer = onOuterFaces(merged, grid, node);
  simplify.collapseBorders = true;
  const std::vector<std::uint32_t> samePosition = positionRepresentatives(merged);
  Collapsed collapsed;
  if (samePosition.empty()) {
    simplify.locked = outer;
    collapsed = simplifyPlain(merged, positions, simplify, center);
  } else {
    collapsed = simplifyTextured(merged, positions, samePosition, outer, simplify);
  }
  MeshPart& mesh = collapsed.mesh;
  // Geometric error: measured against the children's geometry, plus what they already
  // deviate from the finest (the triangle inequality keeps it an upper bound, and makes it
  // non-increasing from parent to child). Sampled both ways by area; the removed vertices'
  // excursions, which area samples could miss, are bounded by the simplifier's own record and
  // by each one's distance to the fan it went into, or to the whole surface for an island that
  // collapsed away (removedVertexBound). Measured before small
  // segments are left out (whose cost is bounded apart: a sample near one would search far for
  // the nearest remaining surface).
  const std::vector<Vec3f> simplifiedPositions = relativeTo(mesh, center);
  const double sampled =
      sampledHausdorff(simplifiedPositions, mesh.indices, positions, merged.indices,
                       options.errorSamples, seedOf(node), /*corners=*/false);
  std::vector<std::uint8_t> shared(mesh.vertexCount());
  for (std::size_t i = 0; i < shared.size(); ++i) shared[i] = outer[collapsed.source[i]];
  const Dropped dropped =
      dropSmallSegments(mesh, collapsed.border, shared, simplify.stopAtTriangles, center);
  SimplifiedNode out;
  out.droppedSegments = dropped.segments;
  // The price of locking: border vertices the tile had to keep.
  out.lockedVertices =
      static_cast<std::uint64_t>(std::count(collapsed.border.begin(), collapsed.border.end(), 1));
  out.simplificationError = std::max({sampled, collapsed.recorded, collapsed.vertexError});
  out.droppedError = dropped.error;
  out.mesh = std::move(mesh);
  return out;
}

}  // namespace lodforge
