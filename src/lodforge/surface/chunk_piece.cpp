#include "lodforge/surface/chunk_piece.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

#include "lodforge/surface/point_index.h"
#include "lodforge/surface/row_shares.h"

namespace lodforge {

namespace {

// A chunk's own corners and the box it computes: a corner of margin round them, for the
// gradient at its faces.
struct ChunkCorners {
  std::array<std::uint64_t, 3> first{};
  std::array<std::uint32_t, 3> size{};
  std::array<std::uint64_t, 3> boxFirst{};
  std::array<std::uint32_t, 3> boxSize{};
};

ChunkCorners cornersOf(const ChunkLayout& layout, std::uint64_t chunk) {
  const std::array<std::uint64_t, 3> at = layout.chunkAt(chunk);
  ChunkCorners c;
  for (std::size_t a = 0; a < 3; ++a) {
    c.first[a] = at[a] * layout.n;
    c.size[a] = static_cast<std::uint32_t>(
        std::min<std::uint64_t>(layout.n + 1, layout.grid.corners[a] - c.first[a]));
    c.boxFirst[a] = c.first[a] > 0 ? c.first[a] - 1 : 0;
    c.boxSize[a] = static_cast<std::uint32_t>(
        std::min<std::uint64_t>(c.first[a] + c.size[a] + 1, layout.grid.corners[a]) -
        c.boxFirst[a]);
  }
  return c;
}

double distance2(Vec3d a, Vec3d b) {
  const Vec3d d = a - b;
  return dot(d, d);
}

// The member nearest to q, the first in input order among equally near ones (the rule the
// streamed colours follow too, so both pick the same point among duplicates).
std::uint32_t nearestMember(const PointIndex& index, std::span<const Vec3d> points, Vec3d q) {
  std::vector<std::uint32_t> found;
  std::vector<double> found2;
  // Two at first: the nearest, and whether the next ties with it (rare but for duplicates).
  for (std::size_t k = 2;; k *= 4) {
    found.resize(k);
    found2.resize(k);
    const std::size_t n = index.nearest(q, k, found.data(), found2.data());
    std::uint32_t best = found[0];
    double best2 = distance2(points[best], q);
    for (std::size_t i = 1; i < n; ++i) {
      const double d2 = distance2(points[found[i]], q);
      if (d2 < best2 || (d2 == best2 && found[i] < best)) best = found[i], best2 = d2;
    }
    // A point not found is at least as far as the farthest found: done unless that one ties.
    if (n < k || found2[n - 1] > best2 * (1 + 1e-9)) return best;
  }
}

// The streamed colours: the piece's vertices bucketed by lattice cell; each point, in input
// order, offers itself to the vertices of the cells within reach, which keep the nearest (the
// first among equals). A vertex's nearest member lies within the radius of a corner with a value
// plus an edge of a tetrahedron (√3 voxels), so `reach` voxels round a point find it; a cell none
// of whose vertices could take the point is passed over. Once the vertices near a point have
// found near points, the reach shrinks to the farthest of those (as of the last refresh(); they
// only get nearer, so a stale bound reaches farther, never less far): in a dense cloud a point
// looks at a few cells, not at the thousand within the radius.
class NearestPoints {
 public:
  NearestPoints(const VoxelGrid& grid, const ChunkCorners& corners, std::span<const Vec3d> vertices,
                double reach)
      : grid_(grid), reach_(reach), vertices_(vertices) {
    for (std::size_t a = 0; a < 3; ++a) {
      first_[a] = corners.first[a];
      cells_[a] = std::max<std::uint32_t>(corners.size[a], 2) - 1;
    }
    std::vector<std::size_t> cellOf(vertices.size());
    start_.assign(cellCount() + 1, 0);
    for (std::size_t v = 0; v < vertices.size(); ++v) {
      const std::array<std::uint32_t, 3> c = cellAround(vertices[v]);
      cellOf[v] = cellIndex(c[0], c[1], c[2]);
      ++start_[cellOf[v] + 1];
    }
    for (std::size_t c = 0; c < cellCount(); ++c) start_[c + 1] += start_[c];
    order_.resize(vertices.size());
    std::vector<std::size_t> next(start_.begin(), start_.end() - 1);
    for (std::size_t v = 0; v < vertices.size(); ++v) order_[next[cellOf[v]]++] = v;
    best2_.assign(vertices.size(), std::numeric_limits<double>::infinity());
    colors_.resize(vertices.size());
    worst2_.resize(cellCount());
    for (std::size_t c = 0; c < cellCount(); ++c)
      worst2_[c] = start_[c] == start_[c + 1] ? -1 : std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < 3; ++a) blocks_[a] = (cells_[a] + kBlock - 1) / kBlock;
    nearBound_.resize(static_cast<std::size_t>(blocks_[0]) * blocks_[1] * blocks_[2]);
    refresh();
  }

  // Per block of cells, the largest best distance of the vertices within reach of it (-1: none).
  void refresh() {
    std::fill(nearBound_.begin(), nearBound_.end(), -1.0);
    for (std::uint32_t k = 0; k < cells_[2]; ++k)
      for (std::uint32_t j = 0; j < cells_[1]; ++j)
        for (std::uint32_t i = 0; i < cells_[0]; ++i) {
          double& bound = nearBound_[blockIndex(i / kBlock, j / kBlock, k / kBlock)];
          bound = std::max(bound, worst2_[cellIndex(i, j, k)]);
        }
    // A cell within reach of a point's cell is at most this many blocks from the point's block.
    const auto across = static_cast<std::uint32_t>(kBlock - 1 + std::ceil(reach_)) / kBlock;
    for (std::size_t axis = 0; axis < 3; ++axis) dilate(axis, across);
  }

  std::uint32_t rows() const { return cells_[1]; }

  // Offers the block's points to the vertices of cells in rows [rowFirst, rowEnd).
  void add(std::span<const CloudRecord> block, std::uint32_t rowFirst, std::uint32_t rowEnd) {
    for (const CloudRecord& r : block) {
      std::array<double, 3> g{};
      for (std::size_t a = 0; a < 3; ++a)
        g[a] = (r.position[static_cast<int>(a)] - grid_.origin[static_cast<int>(a)]) / grid_.voxel -
               static_cast<double>(first_[a]);
      // Out of these rows' reach whatever the bound (most points, with many threads).
      if (floorToInt(g[1] + reach_) < rowFirst || floorToInt(g[1] - reach_) >= rowEnd) continue;
      std::array<std::size_t, 3> at{};  // the block of the point's cell (the nearest in the box)
      for (std::size_t a = 0; a < 3; ++a)
        at[a] = static_cast<std::size_t>(
                    std::clamp<std::int64_t>(floorToInt(g[a]), 0, std::int64_t{cells_[a]} - 1)) /
                kBlock;
      const double bound = nearBound_[blockIndex(at[0], at[1], at[2])];
      if (bound < 0) continue;
      // Beyond sqrt(bound) (and the cells' margin of a thousandth of a voxel) no cell can take it.
      const double reach = std::min(reach_, std::sqrt(bound) / grid_.voxel + 0.01);
      std::array<std::int64_t, 3> lo{}, hi{};
      bool inside = true;
      for (std::size_t a = 0; a < 3 && inside; ++a) {
        const std::int64_t begin = a == 1 ? rowFirst : 0, end = a == 1 ? rowEnd : cells_[a];
        lo[a] = std::max<std::int64_t>(floorToInt(g[a] - reach), begin);
        hi[a] = std::min<std::int64_t>(floorToInt(g[a] + reach), end - 1);
        inside = lo[a] <= hi[a];
      }
      if (!inside) continue;
      for (std::int64_t k = lo[2]; k <= hi[2]; ++k)
        for (std::int64_t j = lo[1]; j <= hi[1]; ++j)
          for (std::int64_t i = lo[0]; i <= hi[0]; ++i) offer(r, {i, j, k});
    }
  }

  std::vector<Rgba8> colors() && { return std::move(colors_); }

 private:
  static constexpr std::uint32_t kBlock = 4;  // cells along a block's edge

  std::size_t cellCount() const {
    return static_cast<std::size_t>(cells_[0]) * cells_[1] * cells_[2];
  }
  std::size_t cellIndex(std::size_t i, std::size_t j, std::size_t k) const {
    return (k * cells_[1] + j) * cells_[0] + i;
  }
  std::size_t blockIndex(std::size_t i, std::size_t j, std::size_t k) const {
    return (k * blocks_[1] + j) * blocks_[0] + i;
  }

  // nearBound_ replaced by the largest within `across` blocks along `axis`.
  void dilate(std::size_t axis, std::uint32_t across) {
    const std::array<std::size_t, 3> step{1, blocks_[0], std::size_t{blocks_[0]} * blocks_[1]};
    const std::vector<double> before = nearBound_;
    for (std::size_t b = 0; b < nearBound_.size(); ++b) {
      const std::size_t along = b / step[axis] % blocks_[axis];
      const std::size_t from = along >= across ? along - across : 0;
      const std::size_t to = std::min<std::size_t>(blocks_[axis] - 1, along + across);
      double bound = -1;
      for (std::size_t t = from; t <= to; ++t)
        bound = std::max(bound, before[b - along * step[axis] + t * step[axis]]);
      nearBound_[b] = bound;
    }
  }

  std::array<std::uint32_t, 3> cellAround(Vec3d p) const {
    std::array<std::uint32_t, 3> c{};
    for (std::size_t a = 0; a < 3; ++a) {
      const double g = (p[static_cast<int>(a)] - grid_.origin[static_cast<int>(a)]) / grid_.voxel -
                       static_cast<double>(first_[a]);
      c[a] = static_cast<std::uint32_t>(
          std::clamp(std::floor(g), 0.0, static_cast<double>(cells_[a] - 1)));
    }
    return c;
  }

  void offer(const CloudRecord& r, std::array<std::int64_t, 3> cell) {
    const std::size_t c =
        cellIndex(static_cast<std::size_t>(cell[0]), static_cast<std::size_t>(cell[1]),
                  static_cast<std::size_t>(cell[2]));
    if (worst2_[c] < 0) return;
    // The point's distance to the cell, the cell a thousandth of a voxel wider (a vertex may
    // round out of it): no vertex in it is nearer.
    double box2 = 0;
    for (std::size_t a = 0; a < 3; ++a) {
      const double lo =
          grid_.origin[static_cast<int>(a)] +
          (static_cast<double>(first_[a]) + static_cast<double>(cell[a]) - 1e-3) * grid_.voxel;
      const double hi = lo + 1.002 * grid_.voxel;
      const double p = r.position[static_cast<int>(a)];
      const double d = p < lo ? lo - p : (p > hi ? p - hi : 0);
      box2 += d * d;
    }
    if (box2 > worst2_[c]) return;
    double worst2 = 0;
    for (std::size_t at = start_[c]; at < start_[c + 1]; ++at) {
      const std::size_t v = order_[at];
      const double d2 = distance2(vertices_[v], r.position);
      if (d2 < best2_[v]) {
        best2_[v] = d2;
        colors_[v] = r.color;
      }
      worst2 = std::max(worst2, best2_[v]);
    }
    worst2_[c] = worst2;
  }

  const VoxelGrid& grid_;
  double reach_;
  std::span<const Vec3d> vertices_;
  std::array<std::uint64_t, 3> first_{};
  std::array<std::uint32_t, 3> cells_{};
  std::vector<std::size_t> start_, order_;  // a cell's vertices: order_[start_[c], start_[c+1])
  std::vector<double> best2_, worst2_;      // per vertex; per cell its vertices' largest (-1: none)
  std::array<std::uint32_t, 3> blocks_{};
  std::vector<double> nearBound_;  // per block of kBlock³ cells (refresh())
  std::vector<Rgba8> colors_;
};

}  // namespace

SurfacePiece heldChunkPiece(const ChunkLayout& layout, std::uint64_t chunk,
                            std::span<const std::uint32_t> members,
                            std::span<const CloudRecord> records, const DistanceOptions& distance,
                            bool colors) {
  assert(chunk < layout.chunkCount());
  assert(std::is_sorted(members.begin(), members.end()) &&
         (members.empty() || members.back() < records.size()));
  const ChunkCorners corners = cornersOf(layout, chunk);
  CornerSums sums(layout.grid, distance, corners.boxFirst, corners.boxSize);
  for (const std::uint32_t m : members) sums.add(records[m].position, records[m].normal);
  SurfacePiece piece = polygonize(layout.grid, sums.values(1), corners.first, corners.size);
  if (colors && !piece.positions.empty()) {
    std::vector<Vec3d> p(members.size());
    for (std::size_t m = 0; m < members.size(); ++m) p[m] = records[members[m]].position;
    const PointIndex index(p);
    piece.colors.resize(piece.positions.size());
    for (std::size_t v = 0; v < piece.positions.size(); ++v)
      piece.colors[v] = records[members[nearestMember(index, p, piece.positions[v])]].color;
  }
  return piece;
}

Result<SurfacePiece> streamedChunkPiece(const ChunkLayout& layout, std::uint64_t chunk,
                                        const std::string& runFile, const DistanceOptions& distance,
                                        bool colors) {
  assert(chunk < layout.chunkCount());
  const ChunkCorners corners = cornersOf(layout, chunk);
  CornerSums sums(layout.grid, distance, corners.boxFirst, corners.boxSize);
  LODFORGE_TRY(forEachRecordBlock(runFile, [&](std::span<const CloudRecord> block) {
    for (const CloudRecord& r : block) sums.add(r.position, r.normal);
    return Status{};
  }));
  SurfacePiece piece = polygonize(layout.grid, sums.values(), corners.first, corners.size);
  if (!colors || piece.positions.empty()) return piece;
  NearestPoints nearest(layout.grid, corners, piece.positions, distance.radius + 2);
  // The bounds start unknown (every point looks the whole reach round it): refreshed after 1 K
  // points, then after as many again as were offered, up to a file block.
  std::size_t offered = 0;
  LODFORGE_TRY(forEachRecordBlock(runFile, [&](std::span<const CloudRecord> block) {
    while (!block.empty()) {
      const std::span<const CloudRecord> part =
          block.first(std::min(block.size(), std::max<std::size_t>(1024, offered)));
      forEachRowShare(nearest.rows(), 0, [&](std::uint32_t first, std::uint32_t end) {
        nearest.add(part, first, end);
      });
      nearest.refresh();
      offered += part.size();
      block = block.subspan(part.size());
    }
    return Status{};
  }));
  piece.colors = std::move(nearest).colors();
  return piece;
}

}  // namespace lodforge
