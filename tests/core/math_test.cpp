#include "lodforge/core/math.h"

#include <bit>
#include <cmath>

#include <gtest/gtest.h>

#include "lodforge/core/quadric.h"

#include "lodforge/core/random.h"

namespace lodforge {
namespace {

void expectNear(Vec3d a, Vec3d b, double tolerance = 1e-9) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(Mat4d, RotationOfUnitQuaternionIsOrthonormal) {
  Random random(11);
  for (int i = 0; i < 100; ++i) {
    Vec3d axis = normalizeOr(
        Vec3d{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)}, Vec3d{0, 0, 1});
    const double angle = random.uniform(-3, 3);
    const Mat4d r = Mat4d::rotation(axis.x * std::sin(angle / 2), axis.y * std::sin(angle / 2),
                                    axis.z * std::sin(angle / 2), std::cos(angle / 2));
    EXPECT_NEAR(r.determinant3(), 1.0, 1e-12);
    expectNear(r.transformVector(axis), axis);  // the axis stays put
    const Vec3d v{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
    EXPECT_NEAR(length(r.transformVector(v)), length(v), 1e-12);
  }
  // 90 degrees about z takes x to y.
  const double h = std::sqrt(0.5);
  expectNear(Mat4d::rotation(0, 0, h, h).transformVector({1, 0, 0}), {0, 1, 0});
}

TEST(Mat4d, ComposesTranslateRotateScale) {
  const Mat4d m = Mat4d::translation({1, 2, 3}) * Mat4d::scale({2, 2, 2});
  expectNear(m.transformPoint({1, 1, 1}), {3, 4, 5});
  expectNear(m.transformVector({1, 1, 1}), {2, 2, 2});
}

TEST(Mat4d, NormalMatrixKeepsNormalsPerpendicularUnderShearAndMirror) {
  Random random(5);
  for (int i = 0; i < 50; ++i) {
    Mat4d m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m.at(r, c) = random.uniform(-2, 2);
    }
    if (std::abs(m.determinant3()) < 0.1) continue;
    // A surface with tangents t1, t2 and normal t1 x t2.
    const Vec3d t1{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
    const Vec3d t2{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
    const Vec3d n = cross(t1, t2);
    const Vec3d transformed = m.normalMatrix().transformVector(n);
    EXPECT_NEAR(dot(transformed, m.transformVector(t1)), 0.0, 1e-9);
    EXPECT_NEAR(dot(transformed, m.transformVector(t2)), 0.0, 1e-9);
    // Same side as the transformed surface's own normal (inverse-transpose, also for mirrors).
    EXPECT_GT(
        dot(transformed, cross(m.transformVector(t1), m.transformVector(t2))) * m.determinant3(),
        0.0);
  }
}

TEST(Quadric, PairEvaluationEqualsSingleEvaluationToTheBit) {
  // The progressive build ranks two neighbours at a time; its collapse order (and so every
  // package) depends on these costs being exactly the single-point values.
  Random random(5);
  for (int i = 0; i < 2000; ++i) {
    Quadric q;
    const Vec3d origin{random.uniform(-1e4, 1e4), random.uniform(-1e4, 1e4),
                       random.uniform(-10, 10)};
    for (int plane = 0; plane < 6; ++plane) {
      const Vec3d normal =
          normalizeOr(Vec3d{random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)},
                      Vec3d{0, 0, 1});
      q += Quadric::fromPlane(normal, origin + Vec3d{random.uniform(-1, 1), 0, 0},
                              random.uniform(1e-6, 10));
    }
    const Vec3d p =
        origin + Vec3d{random.uniform(-2, 2), random.uniform(-2, 2), random.uniform(-2, 2)};
    const Vec3d r =
        origin + Vec3d{random.uniform(-2, 2), random.uniform(-2, 2), random.uniform(-2, 2)};
    double atP = 0, atR = 0;
    q.evaluate(p, r, atP, atR);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(atP), std::bit_cast<std::uint64_t>(q.evaluate(p)));
    EXPECT_EQ(std::bit_cast<std::uint64_t>(atR), std::bit_cast<std::uint64_t>(q.evaluate(r)));
  }
  // And it is the quadric: zero on the plane, the squared distance off it.
  const Quadric floor = Quadric::fromPlane({0, 0, 1}, {0, 0, 2}, 1);
  double on = -1, off = -1;
  floor.evaluate({5, -3, 2}, {1, 1, 5}, on, off);
  EXPECT_DOUBLE_EQ(on, 0.0);
  EXPECT_DOUBLE_EQ(off, 9.0);
}

// The texture quadric of a triangle is the squared distance between a point's coordinates and
// the triangle's linear coordinate function there (its value in the triangle's plane; moving
// along the normal changes nothing), weighted; sums add.
TEST(UvQuadric, MeasuresCoordinatesAgainstTheTrianglesLinearFunction) {
  Random random(11);
  for (int round = 0; round < 50; ++round) {
    std::array<Vec3d, 3> p;
    std::array<Vec2f, 3> uv;
    for (std::size_t k = 0; k < 3; ++k) {
      p[k] = {random.uniform(-3, 3), random.uniform(-3, 3), random.uniform(-3, 3)};
      uv[k] = {float(random.uniform(0, 1)), float(random.uniform(0, 1))};
    }
    const double weight = random.uniform(0.1, 4);
    const UvQuadric q = UvQuadric::fromTriangle(p[0], p[1], p[2], uv[0], uv[1], uv[2], weight);
    // At a point of the triangle (barycentric s, r) lifted off its plane by h.
    const double s = random.uniform(-0.5, 1), r = random.uniform(-0.5, 1);
    const Vec3d n = normalizeOr(cross(p[1] - p[0], p[2] - p[0]), Vec3d{});
    const Vec3d at = p[0] + (p[1] - p[0]) * s + (p[2] - p[0]) * r + n * random.uniform(-1, 1);
    const Vec2f exact{float(uv[0].x + s * (uv[1].x - uv[0].x) + r * (uv[2].x - uv[0].x)),
                      float(uv[0].y + s * (uv[1].y - uv[0].y) + r * (uv[2].y - uv[0].y))};
    EXPECT_NEAR(q.evaluate(at, exact), 0.0, 1e-6 * weight);
    const Vec2f off{exact.x + 0.25f, exact.y - 0.5f};
    const double expected = weight * (double(off.x - exact.x) * (off.x - exact.x) +
                                      double(off.y - exact.y) * (off.y - exact.y));
    EXPECT_NEAR(q.evaluate(at, off), expected, 1e-6 * weight);
    UvQuadric twice = q;
    twice += q;
    EXPECT_NEAR(twice.evaluate(at, off), 2 * expected, 2e-6 * weight);
  }
  // No area, no term.
  const UvQuadric flat =
      UvQuadric::fromTriangle({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {}, {1, 0}, {0, 1}, 1);
  EXPECT_EQ(flat.evaluate({1, 2, 3}, {5, 5}), 0.0);
}

TEST(Box3, EmptyAbsorbsPoints) {
  Aabb box;
  EXPECT_TRUE(box.empty());
  EXPECT_EQ(box.size(), Vec3f{});
  box.add(Vec3f{1, 2, 3});
  EXPECT_FALSE(box.empty());
  box.add(Vec3f{-1, 5, 3});
  EXPECT_EQ(box.min, (Vec3f{-1, 2, 3}));
  EXPECT_EQ(box.max, (Vec3f{1, 5, 3}));
  EXPECT_EQ(box.longestSide(), 3.0f);
  Aabb other;
  box.add(other);  // adding an empty box changes nothing
  EXPECT_EQ(box.min, (Vec3f{-1, 2, 3}));
}

TEST(RoundToLong, EqualsLroundOnEveryFloatNearHalvesAndOnRandomFloats) {
  // The hard cases are the floats next to n + 0.5, where adding 0.5 in float would round.
  for (int n = -40000; n <= 40000; ++n) {
    const float half = static_cast<float>(n) + 0.5f;
    float x = half;
    for (int step = 0; step < 4; ++step) x = std::nextafter(x, -1e9f);
    for (int step = 0; step < 9; ++step, x = std::nextafter(x, 1e9f))
      ASSERT_EQ(roundToLong(x), std::lround(x)) << x;
  }
  Random random(7);
  for (int i = 0; i < 1'000'000; ++i) {
    const auto x = static_cast<float>(random.uniform(-1, 1) * 40000);
    ASSERT_EQ(roundToLong(x), std::lround(x)) << x;
  }
  for (float x : {0.0f, -0.0f, 0.49999997f, -0.49999997f, 1e-30f, -1e-30f, 32767.0f})
    EXPECT_EQ(roundToLong(x), std::lround(x)) << x;
}

TEST(RoundHalfAway, EqualsLroundNextToEveryHalfAndOnRandomDoubles) {
  // Next to n + 0.5 (and 0.5 − 2^-54, where adding 0.5 would round up to 1).
  for (int n = -70000; n <= 70000; ++n) {
    double x = static_cast<double>(n) + 0.5;
    for (int step = 0; step < 3; ++step) x = std::nextafter(x, -1e9);
    for (int step = 0; step < 7; ++step, x = std::nextafter(x, 1e9))
      ASSERT_EQ(roundHalfAway(x), std::lround(x)) << x;
  }
  Random random(11);
  for (int i = 0; i < 1'000'000; ++i) {
    const double x = random.uniform(-1, 1) * 70000;
    ASSERT_EQ(roundHalfAway(x), std::lround(x)) << x;
  }
  for (double x : {0.0, -0.0, 0.49999999999999994, -0.49999999999999994, 1e-300, 65535.0})
    EXPECT_EQ(roundHalfAway(x), std::lround(x)) << x;
}

TEST(Random, IsDeterministicAndIndependentPerItem) {
  Random a(42), b(42);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(a.next(), b.next());
  EXPECT_NE(Random::forItem(42, 1).next(), Random::forItem(42, 2).next());
  Random r(1);
  double sum = 0;
  for (int i = 0; i < 10000; ++i) {
    const double u = r.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
  }
  EXPECT_NEAR(sum / 10000, 0.5, 0.02);
  for (int i = 0; i < 1000; ++i) {
    const double v = r.logUniform(0.01, 10);
    ASSERT_GE(v, 0.01 * 0.999999);
    ASSERT_LE(v, 10.0);
  }
}

}  // namespace
}  // namespace lodforge
