// The camera of the CAD paper's LOD selection (§4): a perspective view with a viewport in pixels,
// and what selection needs from it per object — the projected screen area of the object's box,
// clipped to the viewport (0 outside the frustum), and its distance.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "lodforge/core/math.h"

namespace lodforge {

struct Camera {
  Vec3d position{0, 0, 0};
  Vec3d forward{0, 1, 0};  // unit view direction
  Vec3d up{0, 0, 1};       // unit, orthogonal to forward (normalize() makes it so)
  double fovY = 60.0 * 3.14159265358979323846 / 180.0;  // vertical field of view, radians
  double nearPlane = 0.05;
  double farPlane = 1e5;
  std::uint32_t width = 1280, height = 720;  // viewport in pixels

  static Camera lookAt(Vec3d eye, Vec3d target, Vec3d up, double fovYDegrees, std::uint32_t width,
                       std::uint32_t height);
  void normalize();  // makes forward unit and up orthogonal to it
  Vec3d right() const { return cross(forward, up); }
  double aspect() const { return static_cast<double>(width) / static_cast<double>(height); }
  // Pixels per unit of size at distance 1 along the view direction: a length L at depth d
  // covers L * pixelScale() / d pixels.
  double pixelScale() const;
};

// A camera's view as selection uses it: positions go to view space (x right, y up, z forward)
// relative to the camera, boxes to screen rectangles. Precomputed once per frame.
struct ViewProjection {
  Vec3d origin;  // camera position
  Vec3d right, up, forward;
  double tanX = 1, tanY = 1;  // half-extents of the image plane at depth 1
  double nearPlane = 0.05, farPlane = 1e5;
  double halfWidth = 640, halfHeight = 360;  // pixels

  explicit ViewProjection(const Camera& camera);
};

// Projected area in pixels of an axis-aligned box given by centre and half extents (world
// coordinates relative to `view.origin`), clipped to the viewport; 0 when the box lies outside
// the view frustum. Conservative: the screen rectangle of the box's view-space bounds, its near
// side clamped to the near plane. Branch-free so a loop over many boxes vectorises; T is float
// in the selection's hot loop and double in tests.
template <class T>
inline T projectedArea(T rx, T ry, T rz, T ux, T uy, T uz, T fx, T fy, T fz, T tanX, T tanY,
                       T nearPlane, T farPlane, T halfWidth, T halfHeight, T dx, T dy, T dz, T hx,
                       T hy, T hz) {
  using std::abs, std::max, std::min;
  // View space: centre and the half extents of the rotated box's bounds.
  const T vx = rx * dx + ry * dy + rz * dz, vy = ux * dx + uy * dy + uz * dz,
          vz = fx * dx + fy * dy + fz * dz;
  const T ex = abs(rx) * hx + abs(ry) * hy + abs(rz) * hz;
  const T ey = abs(ux) * hx + abs(uy) * hy + abs(uz) * hz;
  const T ez = abs(fx) * hx + abs(fy) * hy + abs(fz) * hz;
  const T z1 = vz + ez;
  const T z0 = max(vz - ez, nearPlane);
  // Over depths [z0, z1] the box's x/z and y/z spans are widest at the ends.
  const T xlo = min((vx - ex) / z0, (vx - ex) / z1) / tanX,
          xhi = max((vx + ex) / z0, (vx + ex) / z1) / tanX;
  const T ylo = min((vy - ey) / z0, (vy - ey) / z1) / tanY,
          yhi = max((vy + ey) / z0, (vy + ey) / z1) / tanY;
  const T w = max(T(0), min(xhi, T(1)) - max(xlo, T(-1))),
          h = max(T(0), min(yhi, T(1)) - max(ylo, T(-1)));
  const T area = w * halfWidth * h * halfHeight;
  // Entirely behind the near plane or beyond the far plane: nothing.
  // (A bitwise & keeps the loop free of branches; && would not vectorise.)
  const bool inside = (z1 > nearPlane) & (vz - ez < farPlane);
  return inside ? area : T(0);
}

// The same for a box given by its corners, in double: the reference the tests check against.
double projectedArea(const ViewProjection& view, Vec3d boxMin, Vec3d boxMax);

}  // namespace lodforge
