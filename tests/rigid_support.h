// Random point sets and rigid motions for the tests of repeated shapes (core/instances, the
// builder's shape cache).
#pragma once

#include <cmath>
#include <span>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/random.h"

namespace lodforge::test {

inline std::vector<Vec3f> randomPoints(Random& random, int count) {
  std::vector<Vec3f> points;
  for (int i = 0; i < count; ++i)
    points.push_back({static_cast<float>(random.uniform(-1, 1)),
                      static_cast<float>(random.uniform(-1, 1)),
                      static_cast<float>(random.uniform(-1, 1))});
  return points;
}

inline Mat4d randomMotion(Random& random) {
  double q[4], norm = 0;
  for (double& c : q) {
    c = random.uniform(-1, 1);
    norm += c * c;
  }
  norm = std::sqrt(norm);
  Mat4d motion = Mat4d::rotation(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm);
  for (int row = 0; row < 3; ++row) motion.at(row, 3) = random.uniform(-50, 50);
  return motion;
}

inline std::vector<Vec3f> moved(const Mat4d& m, std::span<const Vec3f> points) {
  std::vector<Vec3f> out;
  for (const Vec3f& p : points) {
    const Vec3d q = m.transformPoint(toDouble(p));
    out.push_back({static_cast<float>(q.x), static_cast<float>(q.y), static_cast<float>(q.z)});
  }
  return out;
}

}  // namespace lodforge::test
