// Normals for points that have none, for reconstruction: the direction of least spread of each
// point's k nearest neighbours (PCA), turned consistently — towards a viewpoint, up (+z, for
// airborne and terrestrial scans of the ground), or by propagation over the neighbour graph
// (Hoppe et al. 1992: a minimum spanning tree on 1 − |n_i·n_j|, from the highest point facing
// up), which turns a closed object's normals all outwards.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/surface/point_index.h"

namespace lodforge {

enum class NormalOrientation { kPropagate, kUp, kViewpoint };

struct NormalOptions {
  int neighbours = 12;
  NormalOrientation orientation = NormalOrientation::kPropagate;
  Vec3d viewpoint;  // with kViewpoint
};

// `index` is over `positions` (one k-d tree serves the normals, the spacing and the colours).
std::vector<Vec3f> estimateNormals(std::span<const Vec3d> positions, const PointIndex& index,
                                   const NormalOptions& options);

// The median distance from a point to its nearest neighbour, over up to `samples` points spread
// through the cloud (0 for fewer than two distinct points).
double medianSpacing(std::span<const Vec3d> positions, const PointIndex& index,
                     std::size_t samples = 10'000);

}  // namespace lodforge
