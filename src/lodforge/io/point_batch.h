// A batch of points as every point reader yields it: double positions (geo-scale coordinates
// keep their millimetres), and normals or colours when the file has them.
#pragma once

#include <cstdint>
#include <vector>

#include "lodforge/core/math.h"

namespace lodforge {

struct PointBatch {
  std::uint64_t first = 0;  // index of the batch's first point in the file
  std::vector<Vec3d> positions;
  std::vector<Vec3f> normals;  // empty, or one per point
  std::vector<Rgba8> colors;   // empty, or one per point

  std::size_t size() const { return positions.size(); }
  void clear() {
    positions.clear();
    normals.clear();
    colors.clear();
  }
};

}  // namespace lodforge
