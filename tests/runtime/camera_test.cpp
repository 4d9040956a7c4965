#include "lodforge/runtime/camera.h"

#include <array>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"

namespace lodforge {
namespace {

Vec3d randomUnit(Random& random) {
  for (;;) {
    const Vec3d v{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
    if (length(v) > 0.1 && length(v) <= 1) return v / length(v);
  }
}

Camera randomCamera(Random& random) {
  Camera c = Camera::lookAt({random.uniform(-5, 5), random.uniform(-5, 5), random.uniform(-5, 5)},
                            {random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)},
                            randomUnit(random), random.uniform(20, 100),
                            320 + static_cast<std::uint32_t>(random.below(1600)),
                            200 + static_cast<std::uint32_t>(random.below(900)));
  c.nearPlane = 0.01;
  c.farPlane = 100;
  return c;
}

// A point in view space: x right, y up, z forward.
Vec3d toView(const ViewProjection& v, Vec3d p) {
  const Vec3d d = p - v.origin;
  return {dot(d, v.right), dot(d, v.up), dot(d, v.forward)};
}

// Pixel coordinates of a view-space point in front of the camera (centre at 0).
std::array<double, 2> toPixels(const ViewProjection& v, Vec3d q) {
  return {q.x / q.z / v.tanX * v.halfWidth, q.y / q.z / v.tanY * v.halfHeight};
}

TEST(Camera, LookAtGivesAnOrthonormalFrameEvenWithAParallelUp) {
  Random random(1);
  for (int k = 0; k < 200; ++k) {
    const Camera c = randomCamera(random);
    EXPECT_NEAR(length(c.forward), 1, 1e-12);
    EXPECT_NEAR(length(c.up), 1, 1e-12);
    EXPECT_NEAR(dot(c.forward, c.up), 0, 1e-12);
    EXPECT_NEAR(length(c.right()), 1, 1e-12);
  }
  const Camera down = Camera::lookAt({0, 0, 10}, {0, 0, 0}, {0, 0, 1}, 60, 100, 100);
  EXPECT_NEAR(length(down.up), 1, 1e-12);
  EXPECT_NEAR(dot(down.forward, down.up), 0, 1e-12);
}

TEST(Camera, PixelScaleMatchesTheProjection) {
  // A vertical segment of length L at depth d spans L * pixelScale / d pixels.
  const Camera c = Camera::lookAt({0, 0, 0}, {0, 1, 0}, {0, 0, 1}, 45, 800, 600);
  const ViewProjection v(c);
  const double d = 7.0, length = 0.3;
  const auto top = toPixels(v, toView(v, {0, d, length / 2})),
             bottom = toPixels(v, toView(v, {0, d, -length / 2}));
  EXPECT_NEAR(top[1] - bottom[1], length * c.pixelScale() / d, 1e-9);
}

TEST(ProjectedArea, ExactForAxisAlignedViewsAndBoxesInFront) {
  // With the camera looking along an axis the view-space box is the box itself, so the area is
  // the clipped rectangle of the projected corners exactly.
  Random random(2);
  const Camera c = Camera::lookAt({0, 0, 0}, {0, 1, 0}, {0, 0, 1}, 60, 1000, 500);
  const ViewProjection v(c);
  for (int k = 0; k < 2000; ++k) {
    const Vec3d centre{random.uniform(-8, 8), random.uniform(0.5, 20), random.uniform(-8, 8)};
    const Vec3d half{random.uniform(0.01, 2), random.uniform(0.01, 0.4), random.uniform(0.01, 2)};
    const Vec3d lo = centre - half, hi = centre + half;
    // Reference: project the 8 corners, clip their rectangle to the viewport.
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3d p{(corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y,
                    (corner & 4) ? hi.z : lo.z};
      const auto px = toPixels(v, toView(v, p));
      x0 = std::min(x0, px[0]), x1 = std::max(x1, px[0]), y0 = std::min(y0, px[1]),
      y1 = std::max(y1, px[1]);
    }
    const double w = std::max(0.0, std::min(x1, v.halfWidth) - std::max(x0, -v.halfWidth));
    const double h = std::max(0.0, std::min(y1, v.halfHeight) - std::max(y0, -v.halfHeight));
    EXPECT_NEAR(projectedArea(v, lo, hi), w * h, 1e-6 * std::max(1.0, w * h)) << k;
  }
}

TEST(ProjectedArea, ContainsEverySampledVisiblePointOfTheBoxForAnyView) {
  // Conservative: every surface point of the box that lands on screen lies in the rectangle, so
  // a box that shows anything has an area > 0; a box entirely behind the camera has none.
  Random random(3);
  int visible = 0;
  for (int k = 0; k < 1500; ++k) {
    const Camera c = randomCamera(random);
    const ViewProjection v(c);
    const Vec3d centre{random.uniform(-4, 4), random.uniform(-4, 4), random.uniform(-4, 4)};
    const Vec3d half{random.logUniform(0.01, 2), random.logUniform(0.01, 2),
                     random.logUniform(0.01, 2)};
    const double area = projectedArea(v, centre - half, centre + half);
    const double f = projectedArea<float>(
        float(v.right.x), float(v.right.y), float(v.right.z), float(v.up.x), float(v.up.y),
        float(v.up.z), float(v.forward.x), float(v.forward.y), float(v.forward.z), float(v.tanX),
        float(v.tanY), float(v.nearPlane), float(v.farPlane), float(v.halfWidth),
        float(v.halfHeight), float(centre.x - v.origin.x), float(centre.y - v.origin.y),
        float(centre.z - v.origin.z), float(half.x), float(half.y), float(half.z));
    // Single precision (the selection's hot loop) agrees with double.
    EXPECT_NEAR(f, area, 1e-3 * std::max(area, 1.0)) << k;
    EXPECT_GE(area, 0.0);
    EXPECT_LE(area, 4 * v.halfWidth * v.halfHeight * (1 + 1e-12));
    bool anyOnScreen = false;
    for (int s = 0; s < 300; ++s) {
      Vec3d p{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
      p[static_cast<int>(random.below(3))] = random.below(2) ? 1 : -1;  // on a face
      const Vec3d q = toView(v, centre + Vec3d{p.x * half.x, p.y * half.y, p.z * half.z});
      if (q.z <= v.nearPlane || q.z >= v.farPlane) continue;
      const auto px = toPixels(v, q);
      if (std::abs(px[0]) < v.halfWidth && std::abs(px[1]) < v.halfHeight) anyOnScreen = true;
    }
    if (anyOnScreen) {
      ++visible;
      EXPECT_GT(area, 0.0) << k;
    }
  }
  EXPECT_GT(visible, 300);  // the sample exercised the visible case
}

TEST(ProjectedArea, ZeroBehindBeyondAndBesideTheFrustum) {
  const Camera c = Camera::lookAt({0, 0, 0}, {0, 1, 0}, {0, 0, 1}, 60, 640, 480);
  ViewProjection v(c);
  v.farPlane = 50;
  const Vec3d half{0.5, 0.5, 0.5};
  EXPECT_GT(projectedArea(v, Vec3d{0, 5, 0} - half, Vec3d{0, 5, 0} + half), 0.0);
  EXPECT_EQ(projectedArea(v, Vec3d{0, -5, 0} - half, Vec3d{0, -5, 0} + half), 0.0);    // behind
  EXPECT_EQ(projectedArea(v, Vec3d{0, 60, 0} - half, Vec3d{0, 60, 0} + half), 0.0);    // beyond far
  EXPECT_EQ(projectedArea(v, Vec3d{40, 5, 0} - half, Vec3d{40, 5, 0} + half), 0.0);    // far right
  EXPECT_EQ(projectedArea(v, Vec3d{0, 5, -40} - half, Vec3d{0, 5, -40} + half), 0.0);  // far below
  // Around the camera: the whole viewport.
  EXPECT_NEAR(projectedArea(v, Vec3d{-1, -1, -1}, Vec3d{1, 1, 1}), 640.0 * 480.0, 1e-6);
  // Closer is bigger.
  EXPECT_GT(projectedArea(v, Vec3d{0, 3, 0} - half, Vec3d{0, 3, 0} + half),
            projectedArea(v, Vec3d{0, 6, 0} - half, Vec3d{0, 6, 0} + half));
}

}  // namespace
}  // namespace lodforge
