// Small value types for geometry: vectors, boxes, 4x4 transforms. Plain structs with no
// invariants, laid out as arrays of scalars so spans of them can be written to files as is.
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>

namespace lodforge {

template <class T>
struct Vec3 {
  T x = 0, y = 0, z = 0;

  constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  friend constexpr Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend constexpr Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend constexpr Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
  friend constexpr Vec3 operator*(Vec3 a, T s) { return {a.x * s, a.y * s, a.z * s}; }
  friend constexpr Vec3 operator*(T s, Vec3 a) { return {a.x * s, a.y * s, a.z * s}; }
  friend constexpr Vec3 operator/(Vec3 a, T s) { return {a.x / s, a.y / s, a.z / s}; }
  constexpr Vec3& operator+=(Vec3 b) { return *this = *this + b; }
  constexpr Vec3& operator-=(Vec3 b) { return *this = *this - b; }
  constexpr Vec3& operator*=(T s) { return *this = *this * s; }
  friend constexpr bool operator==(Vec3 a, Vec3 b) = default;
};

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;
static_assert(sizeof(Vec3f) == 12 && sizeof(Vec3d) == 24);

template <class T>
constexpr T dot(Vec3<T> a, Vec3<T> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
constexpr Vec3<T> cross(Vec3<T> a, Vec3<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
T length(Vec3<T> a) {
  return std::sqrt(dot(a, a));
}
template <class T>
Vec3<T> normalizeOr(Vec3<T> a, Vec3<T> fallback) {
  const T len = length(a);
  return len > T(0) && std::isfinite(len) ? a / len : fallback;
}
template <class T>
constexpr Vec3<T> min(Vec3<T> a, Vec3<T> b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <class T>
constexpr Vec3<T> max(Vec3<T> a, Vec3<T> b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <class T>
bool isFinite(Vec3<T> a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
inline Vec3d toDouble(Vec3f a) {
  return {a.x, a.y, a.z};
}
inline Vec3f toFloat(Vec3d a) {
  return {static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z)};
}
// std::lround of a double (halves away from zero) without its libm call, for per-vertex loops:
// x − trunc(x) is exact, so it equals lround for any finite |x| < 2^62 (the contract).
inline long roundHalfAway(double x) {
  assert(std::abs(x) < 0x1p62);  // false for NaN too
  const auto t = static_cast<long>(x);
  const double rest = x - static_cast<double>(t);
  return t + (rest >= 0.5 ? 1 : 0) - (rest <= -0.5 ? 1 : 0);
}

// std::lround of a float the same way: exact, because a float plus or minus 0.5 is exact in
// double.
inline long roundToLong(float x) {
  const double d = x;
  return static_cast<long>(d + (d >= 0 ? 0.5 : -0.5));
}

// A texture coordinate (glTF's TEXCOORD: u right, v down from the image's top-left corner).
struct Vec2f {
  float x = 0, y = 0;
  friend constexpr bool operator==(Vec2f, Vec2f) = default;
};

struct Rgba8 {
  std::uint8_t r = 255, g = 255, b = 255, a = 255;
  friend constexpr bool operator==(Rgba8, Rgba8) = default;
};
static_assert(sizeof(Rgba8) == 4);

// An opaque colour from channels in [0, 1] (clamped, rounded): OBJ's `v x y z r g b` and `Kd`.
inline Rgba8 toRgba8(double r, double g, double b) {
  const auto c = [](double v) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
  };
  return {c(r), c(g), c(b), 255};
}

// Axis-aligned box; a default-constructed box is empty (min > max) and absorbs any point.
template <class T>
struct Box3 {
  Vec3<T> min{std::numeric_limits<T>::max(), std::numeric_limits<T>::max(),
              std::numeric_limits<T>::max()};
  Vec3<T> max{std::numeric_limits<T>::lowest(), std::numeric_limits<T>::lowest(),
              std::numeric_limits<T>::lowest()};

  constexpr bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  constexpr void add(Vec3<T> p) {
    min = lodforge::min(min, p);
    max = lodforge::max(max, p);
  }
  constexpr void add(const Box3& b) {
    if (b.empty()) return;
    add(b.min);
    add(b.max);
  }
  constexpr Vec3<T> center() const { return (min + max) * T(0.5); }
  // Corner i of the 8: bit 0 picks max.x, bit 1 max.y, bit 2 max.z.
  constexpr Vec3<T> corner(int i) const {
    return {(i & 1) ? max.x : min.x, (i & 2) ? max.y : min.y, (i & 4) ? max.z : min.z};
  }
  constexpr Vec3<T> size() const { return empty() ? Vec3<T>{} : max - min; }
  constexpr T longestSide() const {
    const Vec3<T> s = size();
    return std::max({s.x, s.y, s.z});
  }
  friend constexpr bool operator==(const Box3&, const Box3&) = default;
};
using Aabb = Box3<float>;
using Aabbd = Box3<double>;

// Column-major 4x4 transform, as glTF stores it: element (row r, column c) is m[c * 4 + r].
struct Mat4d {
  std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

  static Mat4d translation(Vec3d t) {
    Mat4d r;
    r.m[12] = t.x;
    r.m[13] = t.y;
    r.m[14] = t.z;
    return r;
  }
  static Mat4d scale(Vec3d s) {
    Mat4d r;
    r.m[0] = s.x;
    r.m[5] = s.y;
    r.m[10] = s.z;
    return r;
  }
  // Rotation from a unit quaternion (x, y, z, w), glTF's order.
  static Mat4d rotation(double qx, double qy, double qz, double qw);

  double at(int row, int col) const { return m[static_cast<std::size_t>(col * 4 + row)]; }
  double& at(int row, int col) { return m[static_cast<std::size_t>(col * 4 + row)]; }
  Vec3d transformPoint(Vec3d p) const {
    return {at(0, 0) * p.x + at(0, 1) * p.y + at(0, 2) * p.z + at(0, 3),
            at(1, 0) * p.x + at(1, 1) * p.y + at(1, 2) * p.z + at(1, 3),
            at(2, 0) * p.x + at(2, 1) * p.y + at(2, 2) * p.z + at(2, 3)};
  }
  Vec3d transformVector(Vec3d v) const {
    return {at(0, 0) * v.x + at(0, 1) * v.y + at(0, 2) * v.z,
            at(1, 0) * v.x + at(1, 1) * v.y + at(1, 2) * v.z,
            at(2, 0) * v.x + at(2, 1) * v.y + at(2, 2) * v.z};
  }
  // Transforms normals: the inverse transpose of the upper 3x3 (up to scale, which is
  // removed by normalising afterwards).
  Mat4d normalMatrix() const;
  double determinant3() const;
  friend Mat4d operator*(const Mat4d& a, const Mat4d& b);
};

}  // namespace lodforge
