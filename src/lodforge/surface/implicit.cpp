#include "lodforge/surface/implicit.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

namespace lodforge {

void signedDistances(const VoxelGrid& grid, const OrientedPoints& points,
                     const DistanceOptions& options, CornerValues& values) {
  assert(std::is_sorted(points.ids.begin(), points.ids.end()));
  const auto& size = values.size;
  const std::size_t count = static_cast<std::size_t>(size[0]) * size[1] * size[2];
  std::vector<double> weights(count, 0), sums(count, 0);
  std::vector<Vec3f> offsets(count), directions(count);  // Σ w (p − c), Σ w n (only compared)
  std::vector<std::uint32_t> near(count, 0);
  const double radius = options.radius * grid.voxel, radius2 = radius * radius;
  // Each point adds to the corners within the radius, points in id order: every corner sums
  // its points in the same order whatever box it is computed in.
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
    for (std::int64_t k = lo[2]; k <= hi[2]; ++k) {
      for (std::int64_t j = lo[1]; j <= hi[1]; ++j) {
        for (std::int64_t i = lo[0]; i <= hi[0]; ++i) {
          const Vec3d c =
              grid.position(static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(j),
                            static_cast<std::uint64_t>(k));
          const Vec3d d = c - at;
          const double d2 = dot(d, d);
          if (d2 >= radius2) continue;
          const double w = (1 - d2 / radius2) * (1 - d2 / radius2);
          const std::size_t at3 = values.index(
              static_cast<std::uint32_t>(i - static_cast<std::int64_t>(values.first[0])),
              static_cast<std::uint32_t>(j - static_cast<std::int64_t>(values.first[1])),
              static_cast<std::uint32_t>(k - static_cast<std::int64_t>(values.first[2])));
          weights[at3] += w;
          sums[at3] += w * dot(n, d);
          offsets[at3] = offsets[at3] - toFloat(d * w);
          directions[at3] = directions[at3] + toFloat(n * w);
          ++near[at3];
        }
      }
    }
  }
  values.values.assign(count, std::numeric_limits<float>::quiet_NaN());
  const double edge2 = options.edge * options.edge * radius2;
  for (std::size_t c = 0; c < count; ++c) {
    if (near[c] < options.minPoints) continue;
    // The near points' centroid seen from the corner, along their mean plane.
    const Vec3d offset = toDouble(offsets[c]) * (1 / weights[c]);
    const Vec3d normal = normalizeOr(toDouble(directions[c]), Vec3d{0, 0, 1});
    const Vec3d along = offset - normal * dot(offset, normal);
    if (dot(along, along) > edge2) continue;
    values.values[c] = static_cast<float>(sums[c] / weights[c]);
  }
}

}  // namespace lodforge
