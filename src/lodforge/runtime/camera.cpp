#include "lodforge/runtime/camera.h"

#include <cmath>

namespace lodforge {

Camera Camera::lookAt(Vec3d eye, Vec3d target, Vec3d upHint, double fovYDegrees,
                      std::uint32_t width, std::uint32_t height) {
  Camera c;
  c.position = eye;
  c.forward = target - eye;
  c.up = upHint;
  c.fovY = fovYDegrees * 3.14159265358979323846 / 180.0;
  c.width = width;
  c.height = height;
  c.normalize();
  return c;
}

void Camera::normalize() {
  forward = normalizeOr(forward, Vec3d{0, 1, 0});
  // Gram-Schmidt; an up parallel to forward falls back to another axis.
  Vec3d u = up - forward * dot(up, forward);
  if (length(u) < 1e-9)
    u = std::abs(forward.z) < 0.9 ? Vec3d{0, 0, 1} - forward * forward.z
                                  : Vec3d{1, 0, 0} - forward * forward.x;
  up = normalizeOr(u, Vec3d{0, 0, 1});
}

double Camera::pixelScale() const {
  return 0.5 * static_cast<double>(height) / std::tan(0.5 * fovY);
}

ViewProjection::ViewProjection(const Camera& camera)
    : origin(camera.position),
      right(camera.right()),
      up(camera.up),
      forward(camera.forward),
      tanY(std::tan(0.5 * camera.fovY)),
      nearPlane(camera.nearPlane),
      farPlane(camera.farPlane),
      halfWidth(0.5 * camera.width),
      halfHeight(0.5 * camera.height) {
  tanX = tanY * camera.aspect();
}

double projectedArea(const ViewProjection& v, Vec3d boxMin, Vec3d boxMax) {
  const Vec3d c = (boxMin + boxMax) * 0.5 - v.origin, h = (boxMax - boxMin) * 0.5;
  return projectedArea<double>(v.right.x, v.right.y, v.right.z, v.up.x, v.up.y, v.up.z, v.forward.x,
                               v.forward.y, v.forward.z, v.tanX, v.tanY, v.nearPlane, v.farPlane,
                               v.halfWidth, v.halfHeight, c.x, c.y, c.z, h.x, h.y, h.z);
}

}  // namespace lodforge
