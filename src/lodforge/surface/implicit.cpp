#include "lodforge/surface/implicit.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <tuple>

#include "lodforge/surface/row_shares.h"

namespace lodforge {

CornerSums::CornerSums(const VoxelGrid& grid, const DistanceOptions& options,
                       std::array<std::uint64_t, 3> first, std::array<std::uint32_t, 3> size)
    : grid_(grid), options_(options), first_(first), size_(size) {
  assert(grid.voxel > 0 && options.radius > 0);
}

namespace {

// The corner of a point cell, where its sums are taken from.
Vec3d cellCorner(const VoxelGrid& grid, const std::array<std::int64_t, 3>& key) {
  return grid.origin + Vec3d{static_cast<double>(key[0]), static_cast<double>(key[1]),
                             static_cast<double>(key[2])} *
                           (grid.voxel / kCellSplit);
}

}  // namespace

void CornerSums::add(Vec3d at, Vec3f normal) {
  const std::array<std::int64_t, 3> key = pointCellOf(grid_, at);
  Cell& cell = cells_[key];
  const Vec3d q = at - cellCorner(grid_, key), n = toDouble(normal);
  cell.offset = cell.offset + q;
  cell.normal = cell.normal + n;
  cell.plane += dot(n, q);
  ++cell.count;
}

Vec3d CornerSums::centroidOf(const std::array<std::int64_t, 3>& key, const Cell& cell) const {
  return cellCorner(grid_, key) + cell.offset / static_cast<double>(cell.count);
}

void CornerSums::spread(const std::array<std::int64_t, 3>& key, const Cell& cell,
                        std::vector<Sums>& corners, std::uint32_t rowFirst,
                        std::uint32_t rowEnd) const {
  const double radius = options_.radius * grid_.voxel, radius2 = radius * radius;
  // A row of corners whose (y, z) alone are this far is wholly out of reach (with a margin for
  // the rounding of the full sum, so that no corner within the radius is skipped).
  const double rowReach2 = radius2 * (1 + 1e-9);
  const double inverseRadius2 = 1 / radius2, inverseVoxel = 1 / grid_.voxel;
  const Vec3d o = cellCorner(grid_, key);
  const auto count = static_cast<double>(cell.count);
  const Vec3d at = centroidOf(key, cell);
  std::array<std::int64_t, 3> lo{}, hi{};
  // Rows first: a thread owning a share of the rows passes over most cells here.
  for (const std::size_t a : {std::size_t{1}, std::size_t{0}, std::size_t{2}}) {
    const double g = (at[static_cast<int>(a)] - grid_.origin[static_cast<int>(a)]) / grid_.voxel;
    const auto first = static_cast<std::int64_t>(first_[a]);
    const std::int64_t begin = a == 1 ? first + rowFirst : first;
    const std::int64_t end = a == 1 ? first + rowEnd : first + size_[a];
    lo[a] = std::max<std::int64_t>(ceilToInt(g - options_.radius), begin);
    hi[a] = std::min<std::int64_t>(floorToInt(g + options_.radius), end - 1);
    if (lo[a] > hi[a]) return;
  }
  const double gx = (at.x - grid_.origin.x) / grid_.voxel;
  const Vec3f direction = toFloat(cell.normal);
  for (std::int64_t k = lo[2]; k <= hi[2]; ++k) {
    for (std::int64_t j = lo[1]; j <= hi[1]; ++j) {
      const Vec3d rowStart =
          grid_.position(static_cast<std::uint64_t>(lo[0]), static_cast<std::uint64_t>(j),
                         static_cast<std::uint64_t>(k));
      const Vec3d row = rowStart - at;
      const double across2 = row.y * row.y + row.z * row.z;
      if (across2 >= rowReach2) continue;
      // Σ n·(c − p) = Σn·(c − o) − Σ n·(p − o); the y and z terms are the row's.
      const double planeAcross =
          cell.normal.y * (rowStart.y - o.y) + cell.normal.z * (rowStart.z - o.z) - cell.plane;
      Sums* line =
          &corners[(static_cast<std::size_t>(k - static_cast<std::int64_t>(first_[2])) * size_[1] +
                    static_cast<std::size_t>(j - static_cast<std::int64_t>(first_[1]))) *
                   size_[0]];
      // The row's corners within reach, a corner wider each way (the test below decides).
      // (Truncation is floor for these non-negative grid coordinates; a corner's margin covers
      // the rest.)
      const double half = std::sqrt(rowReach2 - across2) * inverseVoxel;
      const std::int64_t first =
          std::max(lo[0], static_cast<std::int64_t>(std::max(0.0, gx - half)) - 1);
      const std::int64_t last = std::min(hi[0], static_cast<std::int64_t>(gx + half) + 1);
      for (std::int64_t i = first; i <= last; ++i) {
        const double cx = grid_.origin.x + static_cast<double>(i) * grid_.voxel;
        const double dx = cx - at.x;
        const double d2 = dx * dx + across2;
        if (d2 >= radius2) continue;
        const double t = 1 - d2 * inverseRadius2;
        const double w = t * t, wn = w * count;
        Sums& corner = line[i - static_cast<std::int64_t>(first_[0])];
        corner.weight += wn;
        corner.sum += w * (cell.normal.x * (cx - o.x) + planeAcross);
        corner.offset = corner.offset - toFloat(Vec3d{dx, row.y, row.z} * wn);
        corner.direction = corner.direction + direction * static_cast<float>(w);
        corner.near += cell.count;
      }
    }
  }
}

CornerValues CornerSums::values(int threads) const {
  assert(threads >= 0);
  // The cells in global order (z, y, x): the order every corner adds them in.
  using Entry = std::pair<const std::array<std::int64_t, 3>, Cell>;
  std::vector<const Entry*> order;
  order.reserve(cells_.size());
  for (const Entry& entry : cells_) order.push_back(&entry);
  std::sort(order.begin(), order.end(), [](const Entry* a, const Entry* b) {
    const auto& p = a->first;
    const auto& q = b->first;
    return std::tie(p[2], p[1], p[0]) < std::tie(q[2], q[1], q[0]);
  });
  std::vector<Sums> corners(static_cast<std::size_t>(size_[0]) * size_[1] * size_[2]);
  if (rowShareThreads(threads) == 1) {
    for (const Entry* entry : order) spread(entry->first, entry->second, corners, 0, size_[1]);
  } else {
    // Each share of the rows passes over the cells that reach none of its rows by two integer
    // comparisons: the rows a cell's centroid reaches (a row more each way for rounding).
    std::vector<std::pair<std::int64_t, std::int64_t>> reached(order.size());
    for (std::size_t e = 0; e < order.size(); ++e) {
      const double y = centroidOf(order[e]->first, order[e]->second).y;
      const double g = (y - grid_.origin.y) / grid_.voxel - static_cast<double>(first_[1]);
      reached[e] = {floorToInt(g - options_.radius) - 1, floorToInt(g + options_.radius) + 1};
    }
    forEachRowShare(size_[1], threads, [&](std::uint32_t first, std::uint32_t end) {
      for (std::size_t e = 0; e < order.size(); ++e)
        if (reached[e].second >= first && reached[e].first < end)
          spread(order[e]->first, order[e]->second, corners, first, end);
    });
  }
  CornerValues values{first_, size_, {}};
  values.values.assign(corners.size(), std::numeric_limits<float>::quiet_NaN());
  const double radius = options_.radius * grid_.voxel;
  const double edge2 = options_.edge * options_.edge * radius * radius;
  for (std::size_t c = 0; c < corners.size(); ++c) {
    const Sums& corner = corners[c];
    if (corner.near < options_.minPoints) continue;
    // The near points' centroid seen from the corner, along their mean plane.
    const Vec3d offset = toDouble(corner.offset) * (1 / corner.weight);
    const Vec3d normal = normalizeOr(toDouble(corner.direction), Vec3d{0, 0, 1});
    const Vec3d along = offset - normal * dot(offset, normal);
    if (dot(along, along) > edge2) continue;
    values.values[c] = static_cast<float>(corner.sum / corner.weight);
  }
  return values;
}

void signedDistances(const VoxelGrid& grid, const OrientedPoints& points,
                     const DistanceOptions& options, CornerValues& values) {
  assert(points.normals.size() == points.positions.size());
  CornerSums sums(grid, options, values.first, values.size);
  for (std::size_t p = 0; p < points.positions.size(); ++p)
    sums.add(points.positions[p], points.normals[p]);
  values = sums.values();
}

}  // namespace lodforge
