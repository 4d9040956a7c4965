// Garland–Heckbert quadric error: the sum of squared distances to a set of planes, stored as the
// symmetric 4x4 matrix's 10 distinct entries (double, since sums over many planes cancel).
#pragma once

#include "lodforge/core/math.h"

namespace lodforge {

struct Quadric {
  // Upper triangle of  [a2 ab ac ad; . b2 bc bd; . . c2 cd; . . . d2]  for plane ax+by+cz+d = 0.
  double a2 = 0, ab = 0, ac = 0, ad = 0, b2 = 0, bc = 0, bd = 0, c2 = 0, cd = 0, d2 = 0;

  // The plane through `point` with unit `normal`, scaled by `weight` (e.g. triangle area).
  static Quadric fromPlane(Vec3d normal, Vec3d point, double weight) {
    const double d = -dot(normal, point);
    const double a = normal.x, b = normal.y, c = normal.z;
    return {weight * a * a, weight * a * b, weight * a * c, weight * a * d, weight * b * b,
            weight * b * c, weight * b * d, weight * c * c, weight * c * d, weight * d * d};
  }

  Quadric& operator+=(const Quadric& o) {
    a2 += o.a2, ab += o.ab, ac += o.ac, ad += o.ad, b2 += o.b2;
    bc += o.bc, bd += o.bd, c2 += o.c2, cd += o.cd, d2 += o.d2;
    return *this;
  }
  friend Quadric operator+(Quadric a, const Quadric& b) { return a += b; }

  // v^T Q v for v = (p, 1): the weighted sum of squared plane distances at p.
  double evaluate(Vec3d p) const {
    const double x = p.x, y = p.y, z = p.z;
    return a2 * x * x + 2 * ab * x * y + 2 * ac * x * z + 2 * ad * x + b2 * y * y + 2 * bc * y * z +
           2 * bd * y + c2 * z * z + 2 * cd * z + d2;
  }

  // evaluate() at two points at once, in SSE2 lanes: the same operations in the same order,
  // so each lane equals evaluate() to the bit (no fused multiply-add on the x86-64 baseline).
  void evaluate(Vec3d p, Vec3d r, double& atP, double& atR) const {
    using Pair = double __attribute__((vector_size(16)));
    const Pair x = {p.x, r.x}, y = {p.y, r.y}, z = {p.z, r.z};
    const Pair sum = a2 * x * x + 2 * ab * x * y + 2 * ac * x * z + 2 * ad * x + b2 * y * y +
                     2 * bc * y * z + 2 * bd * y + c2 * z * z + 2 * cd * z + d2;
    atP = sum[0];
    atR = sum[1];
  }
};

}  // namespace lodforge
