// Garland–Heckbert quadric error: the sum of squared distances to a set of planes, stored as the
// symmetric 4x4 matrix's 10 distinct entries (double, since sums over many planes cancel). And its
// texture-coordinate counterpart, UvQuadric.
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

// The texture-coordinate error of a point with its own coordinates (Hoppe 1999's attribute part of
// the quadric, kept apart from the geometry's): over each triangle the coordinates are a linear
// function uv(p) = g_k . p + d_k of position (the gradient in the triangle's plane), and the error
// is the weighted sum over triangles of |uv(p) - uv|^2. Zero wherever the parametrization is
// affine, so it measures how far a collapse bends the texture, not the surface.
struct UvQuadric {
  // Sum of w * (g_k . p - t_k + d_k)^2 over triangles and k = u, v, expanded: p^T m p (m's upper
  // triangle xx xy xz yy yz zz), weight * |t|^2, -2 t_k (gk . p), 2 (e . p), -2 f_k t_k, c.
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0, weight = 0;
  Vec3d gu{}, gv{}, e{};
  double fu = 0, fv = 0, c = 0;

  // The triangle (a, b, d) with coordinates (ta, tb, td), weighted by `weight` (area times the
  // squared texture-to-model scale, so the error is in squared model units). A triangle with no
  // area adds nothing.
  static UvQuadric fromTriangle(Vec3d a, Vec3d b, Vec3d d, Vec2f ta, Vec2f tb, Vec2f td,
                                double weight) {
    const Vec3d e1 = b - a, e2 = d - a, n = cross(e1, e2);
    const double n2 = dot(n, n);
    if (!(n2 > 0)) return {};
    // The gradient of the linear function with values 0, s, t at a, b, d: (s (e2 x n) +
    // t (n x e1)) / |n|^2, the dual basis of the edges in the triangle's plane.
    const Vec3d d1 = cross(e2, n) / n2, d2 = cross(n, e1) / n2;
    const Vec3d g0 = d1 * double(tb.x - ta.x) + d2 * double(td.x - ta.x);
    const Vec3d g1 = d1 * double(tb.y - ta.y) + d2 * double(td.y - ta.y);
    const double k0 = ta.x - dot(g0, a), k1 = ta.y - dot(g1, a);
    UvQuadric q;
    q.xx = weight * (g0.x * g0.x + g1.x * g1.x), q.xy = weight * (g0.x * g0.y + g1.x * g1.y);
    q.xz = weight * (g0.x * g0.z + g1.x * g1.z), q.yy = weight * (g0.y * g0.y + g1.y * g1.y);
    q.yz = weight * (g0.y * g0.z + g1.y * g1.z), q.zz = weight * (g0.z * g0.z + g1.z * g1.z);
    q.weight = weight;
    q.gu = g0 * weight, q.gv = g1 * weight, q.e = (g0 * k0 + g1 * k1) * weight;
    q.fu = weight * k0, q.fv = weight * k1, q.c = weight * (k0 * k0 + k1 * k1);
    return q;
  }

  UvQuadric& operator+=(const UvQuadric& o) {
    xx += o.xx, xy += o.xy, xz += o.xz, yy += o.yy, yz += o.yz, zz += o.zz, weight += o.weight;
    gu = gu + o.gu, gv = gv + o.gv, e = e + o.e;
    fu += o.fu, fv += o.fv, c += o.c;
    return *this;
  }

  // The weighted squared coordinate error of point p carrying coordinates t.
  double evaluate(Vec3d p, Vec2f t) const {
    const double x = p.x, y = p.y, z = p.z, u = t.x, v = t.y;
    return xx * x * x + 2 * xy * x * y + 2 * xz * x * z + yy * y * y + 2 * yz * y * z + zz * z * z +
           weight * (u * u + v * v) - 2 * u * dot(gu, p) - 2 * v * dot(gv, p) + 2 * dot(e, p) -
           2 * fu * u - 2 * fv * v + c;
  }
};

}  // namespace lodforge
