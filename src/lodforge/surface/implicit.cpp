#include "lodforge/surface/implicit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace lodforge {

namespace {

// The bits of v spread to every third place (21 bits in, 63 out).
std::uint64_t spread3(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

}  // namespace

std::vector<std::uint32_t> sumOrder(const VoxelGrid& grid, std::span<const Vec3d> positions,
                                    std::span<const std::uint64_t> ids) {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(positions.size());
  for (std::size_t p = 0; p < positions.size(); ++p) {
    std::uint64_t key = 0;
    for (int a = 0; a < 3; ++a) {
      const double g = std::floor((positions[p][a] - grid.origin[a]) / grid.voxel);
      key |= spread3(static_cast<std::uint64_t>(std::max(0.0, g))) << a;
    }
    keyed[p] = {key, static_cast<std::uint32_t>(p)};
  }
  std::sort(keyed.begin(), keyed.end(), [&](const auto& x, const auto& y) {
    return x.first != y.first ? x.first < y.first : ids[x.second] < ids[y.second];
  });
  std::vector<std::uint32_t> order(keyed.size());
  for (std::size_t i = 0; i < keyed.size(); ++i) order[i] = keyed[i].second;
  return order;
}

void signedDistances(const VoxelGrid& grid, const OrientedPoints& points,
                     const DistanceOptions& options, CornerValues& values) {
  const auto& size = values.size;
  const std::size_t count = static_cast<std::size_t>(size[0]) * size[1] * size[2];
  // One corner's sums side by side: a point's update touches one cache line per corner.
  struct Sums {
    double weight = 0, sum = 0;
    Vec3f offset, direction;  // Σ w (p − c), Σ w n (only compared)
    std::uint32_t near = 0;
  };
  std::vector<Sums> corners(count);
  const double radius = options.radius * grid.voxel, radius2 = radius * radius;
  // A row of corners whose (y, z) alone are this far is wholly out of reach (with a margin for
  // the rounding of the full sum, so that no corner within the radius is skipped).
  const double rowReach2 = radius2 * (1 + 1e-9);
  const double inverseRadius2 = 1 / radius2, inverseVoxel = 1 / grid.voxel;
  // Each point adds to the corners within the radius, points in the one order every box uses:
  // every corner sums its points in the same order whatever box it is computed in.
  for (std::size_t p = 0; p < points.positions.size(); ++p) {
    const Vec3d at = points.positions[p];
    const Vec3d n = toDouble(points.normals[p]);
    std::array<std::int64_t, 3> lo{}, hi{};
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      const double g = (at[a] - grid.origin[a]) / grid.voxel;
      const auto first = static_cast<std::int64_t>(values.first[static_cast<std::size_t>(a)]);
      lo[static_cast<std::size_t>(a)] =
          std::max<std::int64_t>(static_cast<std::int64_t>(std::ceil(g - options.radius)), first);
      hi[static_cast<std::size_t>(a)] = std::min<std::int64_t>(
          static_cast<std::int64_t>(std::floor(g + options.radius)),
          first + static_cast<std::int64_t>(size[static_cast<std::size_t>(a)]) - 1);
      inside = inside && lo[static_cast<std::size_t>(a)] <= hi[static_cast<std::size_t>(a)];
    }
    if (!inside) continue;
    const double gx = (at.x - grid.origin.x) / grid.voxel;
    for (std::int64_t k = lo[2]; k <= hi[2]; ++k) {
      for (std::int64_t j = lo[1]; j <= hi[1]; ++j) {
        const Vec3d row =
            grid.position(static_cast<std::uint64_t>(lo[0]), static_cast<std::uint64_t>(j),
                          static_cast<std::uint64_t>(k)) -
            at;
        const double across2 = row.y * row.y + row.z * row.z;
        if (across2 >= rowReach2) continue;
        Sums* line = &corners[values.index(
            0, static_cast<std::uint32_t>(j - static_cast<std::int64_t>(values.first[1])),
            static_cast<std::uint32_t>(k - static_cast<std::int64_t>(values.first[2])))];
        // The row's corners within reach, a corner wider each way (the test below decides).
        // (Truncation is floor for these non-negative grid coordinates; a corner's margin covers
        // the rest.)
        const double half = std::sqrt(rowReach2 - across2) * inverseVoxel;
        const std::int64_t first =
            std::max(lo[0], static_cast<std::int64_t>(std::max(0.0, gx - half)) - 1);
        const std::int64_t last = std::min(hi[0], static_cast<std::int64_t>(gx + half) + 1);
        for (std::int64_t i = first; i <= last; ++i) {
          const Vec3d c =
              grid.position(static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(j),
                            static_cast<std::uint64_t>(k));
          const Vec3d d = c - at;
          const double d2 = dot(d, d);
          if (d2 >= radius2) continue;
          const double t = 1 - d2 * inverseRadius2;
          const double w = t * t;
          Sums& corner = line[i - static_cast<std::int64_t>(values.first[0])];
          corner.weight += w;
          corner.sum += w * dot(n, d);
          corner.offset = corner.offset - toFloat(d * w);
          corner.direction = corner.direction + toFloat(n * w);
          ++corner.near;
        }
      }
    }
  }
  values.values.assign(count, std::numeric_limits<float>::quiet_NaN());
  const double edge2 = options.edge * options.edge * radius2;
  for (std::size_t c = 0; c < count; ++c) {
    const Sums& corner = corners[c];
    if (corner.near < options.minPoints) continue;
    // The near points' centroid seen from the corner, along their mean plane.
    const Vec3d offset = toDouble(corner.offset) * (1 / corner.weight);
    const Vec3d normal = normalizeOr(toDouble(corner.direction), Vec3d{0, 0, 1});
    const Vec3d along = offset - normal * dot(offset, normal);
    if (dot(along, along) > edge2) continue;
    values.values[c] = static_cast<float>(corner.sum / corner.weight);
  }
}

}  // namespace lodforge
