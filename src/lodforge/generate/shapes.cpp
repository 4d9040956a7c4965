#include "lodforge/generate/shapes.h"

#include <cassert>
#include <cmath>
#include <numeric>

#include "lodforge/core/mesh.h"

namespace lodforge {

namespace {
constexpr double kTwoPi = 6.283185307179586;

float cross2(Vec2f o, Vec2f a, Vec2f b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

bool insideTriangle(Vec2f p, Vec2f a, Vec2f b, Vec2f c) {
  return cross2(a, b, p) >= 0 && cross2(b, c, p) >= 0 && cross2(c, a, p) >= 0;
}
}  // namespace

void addBox(PartMesh& mesh, Vec3f size, int subdivisions) {
  assert(subdivisions >= 1);
  const Vec3f h = size * 0.5f;
  // (normal, u axis, v axis) with u x v = normal, so every face winds counter-clockwise outside.
  struct Face {
    Vec3f normal, u, v;
  };
  const Face faces[6] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
                         {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
                         {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
  auto scale = [&](Vec3f axis) { return Vec3f{axis.x * h.x, axis.y * h.y, axis.z * h.z}; };
  const int n = subdivisions;
  for (const Face& f : faces) {
    const Vec3f centre = scale(f.normal), du = scale(f.u), dv = scale(f.v);
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        const float s = 2.0f * static_cast<float>(i) / static_cast<float>(n) - 1.0f;
        const float t = 2.0f * static_cast<float>(j) / static_cast<float>(n) - 1.0f;
        mesh.vertex(centre + du * s + dv * t, f.normal);
      }
    }
    const auto row = static_cast<std::uint32_t>(n + 1);
    for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(n); ++j) {
      for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(n); ++i) {
        const std::uint32_t a = base + j * row + i;
        mesh.quad(a, a + 1, a + row + 1, a + row);
      }
    }
  }
}

void addCylinderSide(PartMesh& mesh, float radius, float z0, float z1, int segments, int rings,
                     bool outward) {
  assert(segments >= 3 && rings >= 1);
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  const auto s = static_cast<std::uint32_t>(segments);
  for (int r = 0; r <= rings; ++r) {
    const float z = z0 + (z1 - z0) * static_cast<float>(r) / static_cast<float>(rings);
    for (int k = 0; k < segments; ++k) {
      const double a = kTwoPi * k / segments;
      const Vec3f radial{static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0};
      mesh.vertex(Vec3f{radial.x * radius, radial.y * radius, z}, outward ? radial : -radial);
    }
  }
  for (std::uint32_t r = 0; r < static_cast<std::uint32_t>(rings); ++r) {
    for (std::uint32_t k = 0; k < s; ++k) {
      const std::uint32_t a = base + r * s + k, b = base + r * s + (k + 1) % s;
      const std::uint32_t c = b + s, d = a + s;
      if (outward)
        mesh.quad(a, b, c, d);
      else
        mesh.quad(a, d, c, b);
    }
  }
}

void addDisk(PartMesh& mesh, float radius, float z, int segments, bool up) {
  const Vec3f normal{0, 0, up ? 1.0f : -1.0f};
  const std::uint32_t centre = mesh.vertex({0, 0, z}, normal);
  for (int k = 0; k < segments; ++k) {
    const double a = kTwoPi * k / segments;
    mesh.vertex(
        {static_cast<float>(std::cos(a)) * radius, static_cast<float>(std::sin(a)) * radius, z},
        normal);
  }
  const auto s = static_cast<std::uint32_t>(segments);
  for (std::uint32_t k = 0; k < s; ++k) {
    const std::uint32_t a = centre + 1 + k, b = centre + 1 + (k + 1) % s;
    if (up)
      mesh.triangle(centre, a, b);
    else
      mesh.triangle(centre, b, a);
  }
}

void addAnnulus(PartMesh& mesh, float inner, float outer, float z, int segments, bool up) {
  const Vec3f normal{0, 0, up ? 1.0f : -1.0f};
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  for (int k = 0; k < segments; ++k) {
    const double a = kTwoPi * k / segments;
    const float c = static_cast<float>(std::cos(a)), s = static_cast<float>(std::sin(a));
    mesh.vertex({c * inner, s * inner, z}, normal);
    mesh.vertex({c * outer, s * outer, z}, normal);
  }
  const auto s = static_cast<std::uint32_t>(segments);
  for (std::uint32_t k = 0; k < s; ++k) {
    const std::uint32_t i0 = base + 2 * k, o0 = i0 + 1;
    const std::uint32_t i1 = base + 2 * ((k + 1) % s), o1 = i1 + 1;
    if (up)
      mesh.quad(i0, o0, o1, i1);
    else
      mesh.quad(i0, i1, o1, o0);
  }
}

bool triangulatePolygon(std::span<const Vec2f> polygon, std::vector<std::uint32_t>& triangles) {
  std::vector<std::uint32_t> remaining(polygon.size());
  std::iota(remaining.begin(), remaining.end(), 0u);
  while (remaining.size() > 3) {
    bool clipped = false;
    for (std::size_t i = 0; i < remaining.size() && !clipped; ++i) {
      const std::uint32_t prev = remaining[(i + remaining.size() - 1) % remaining.size()];
      const std::uint32_t cur = remaining[i];
      const std::uint32_t next = remaining[(i + 1) % remaining.size()];
      const Vec2f a = polygon[prev], b = polygon[cur], c = polygon[next];
      if (cross2(a, b, c) <= 0) continue;  // reflex corner: not an ear
      bool empty = true;
      for (std::uint32_t other : remaining) {
        if (other == prev || other == cur || other == next) continue;
        if (insideTriangle(polygon[other], a, b, c)) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      triangles.insert(triangles.end(), {prev, cur, next});
      remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
    }
    if (!clipped) return false;
  }
  if (remaining.size() == 3)
    triangles.insert(triangles.end(), {remaining[0], remaining[1], remaining[2]});
  return true;
}

void addExtrusion(PartMesh& mesh, std::span<const Vec2f> profile, float length, int segments) {
  const std::size_t n = profile.size();
  // Sides: each profile edge is a flat strip with its own outward normal.
  for (std::size_t e = 0; e < n; ++e) {
    const Vec2f p = profile[e], q = profile[(e + 1) % n];
    const Vec3f normal = normalizeOr(Vec3f{q.y - p.y, p.x - q.x, 0}, Vec3f{1, 0, 0});
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (int s = 0; s <= segments; ++s) {
      const float z = length * static_cast<float>(s) / static_cast<float>(segments);
      mesh.vertex({p.x, p.y, z}, normal);
      mesh.vertex({q.x, q.y, z}, normal);
    }
    for (std::uint32_t s = 0; s < static_cast<std::uint32_t>(segments); ++s) {
      const std::uint32_t a = base + 2 * s;
      mesh.quad(a, a + 1, a + 3, a + 2);
    }
  }
  // Caps.
  std::vector<std::uint32_t> cap;
  const bool simple = triangulatePolygon(profile, cap);
  assert(simple);
  (void)simple;
  for (int end = 0; end < 2; ++end) {
    const bool top = end == 1;
    const Vec3f normal{0, 0, top ? 1.0f : -1.0f};
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (const Vec2f& p : profile) mesh.vertex({p.x, p.y, top ? length : 0.0f}, normal);
    for (std::size_t t = 0; t < cap.size(); t += 3) {
      if (top)
        mesh.triangle(base + cap[t], base + cap[t + 1], base + cap[t + 2]);
      else
        mesh.triangle(base + cap[t], base + cap[t + 2], base + cap[t + 1]);
    }
  }
}

void addPerforatedPlate(PartMesh& mesh, int columns, int rows, float cell, float holeRadius,
                        int holeSegments) {
  assert(holeSegments % 8 == 0 && holeRadius > 0 && holeRadius < 0.5f);
  const int m = holeSegments, eighth = m / 8;
  // tan of the hole angles within one side, exactly antisymmetric and exactly 1 at the corners,
  // so neighbouring cells compute bit-identical points on their shared edge.
  std::vector<float> tangent(static_cast<std::size_t>(2 * eighth + 1));
  for (int j = 0; j <= eighth; ++j) {
    const float t = j == eighth ? 1.0f : static_cast<float>(std::tan(kTwoPi * j / m));
    tangent[static_cast<std::size_t>(eighth + j)] = t;
    tangent[static_cast<std::size_t>(eighth - j)] = -t;
  }
  auto tanAt = [&](int j) { return tangent[static_cast<std::size_t>(j + eighth)]; };
  const float half = 0.5f * cell;
  const float x0 = -half * static_cast<float>(columns), y0 = -half * static_cast<float>(rows);
  const Vec3f up{0, 0, 1};
  PartMesh sheet;
  for (int row = 0; row < rows; ++row) {
    for (int column = 0; column < columns; ++column) {
      const float left = x0 + static_cast<float>(column) * cell,
                  right = x0 + static_cast<float>(column + 1) * cell;
      const float bottom = y0 + static_cast<float>(row) * cell,
                  top = y0 + static_cast<float>(row + 1) * cell;
      const float cx = x0 + (static_cast<float>(column) + 0.5f) * cell;
      const float cy = y0 + (static_cast<float>(row) + 0.5f) * cell;
      // The square's point at hole angle k: edge coordinates at corners, centre + tan inside.
      auto squarePoint = [&](int k) -> Vec3f {
        const int side = ((k + eighth) % m) / (2 * eighth);  // 0 right, 1 top, 2 left, 3 bottom
        const int j = (k + eighth) % m - eighth - side * 2 * eighth;
        const bool corner = j == eighth || j == -eighth;
        switch (side) {
          case 0:
            return {right, corner ? (j > 0 ? top : bottom) : cy + half * tanAt(j), 0};
          case 1:
            return {corner ? (j > 0 ? left : right) : cx - half * tanAt(j), top, 0};
          case 2:
            return {left, corner ? (j > 0 ? bottom : top) : cy - half * tanAt(j), 0};
          default:
            return {corner ? (j > 0 ? right : left) : cx + half * tanAt(j), bottom, 0};
        }
      };
      const auto base = static_cast<std::uint32_t>(sheet.positions.size());
      for (int k = 0; k < m; ++k) {
        const double a = kTwoPi * k / m;
        sheet.vertex({cx + holeRadius * cell * static_cast<float>(std::cos(a)),
                      cy + holeRadius * cell * static_cast<float>(std::sin(a)), 0},
                     up);
        sheet.vertex(squarePoint(k), up);
      }
      for (std::uint32_t k = 0; k < static_cast<std::uint32_t>(m); ++k) {
        const std::uint32_t c0 = base + 2 * k, s0 = c0 + 1;
        const std::uint32_t c1 = base + 2 * ((k + 1) % static_cast<std::uint32_t>(m)), s1 = c1 + 1;
        sheet.triangle(c0, s0, s1);
        sheet.triangle(c0, s1, c1);
      }
    }
  }
  // One sheet: weld the shared cell edges.
  std::vector<std::uint32_t> remap(sheet.positions.size());
  const std::uint32_t unique = weldVertices(sheet.positions, {}, {}, WeldOptions{}, remap);
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.resize(base + unique);
  mesh.normals.resize(base + unique, up);
  remapVertexAttribute<Vec3f>(sheet.positions, remap, std::span(mesh.positions).subspan(base));
  for (std::uint32_t i : sheet.indices) mesh.indices.push_back(base + remap[i]);
}

}  // namespace lodforge
