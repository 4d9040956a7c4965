#include "lodforge/io/glb_instances.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <unordered_map>

namespace lodforge {
namespace {

// An orthonormal, right-handed frame of three points: columns u, v, w.
struct Frame {
  Vec3d u, v, w;
};

std::optional<Frame> frameOf(Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d ab = b - a, normal = cross(ab, c - a);
  const double lengthAb = length(ab), lengthNormal = length(normal);
  if (!(lengthAb > 0) || !(lengthNormal > 0)) return std::nullopt;
  Frame f;
  f.u = ab / lengthAb;
  f.w = normal / lengthNormal;
  f.v = cross(f.w, f.u);
  return f;
}

// Three vertices far apart and far from collinear, so the frames they span are well conditioned.
std::optional<std::array<std::size_t, 3>> spanningVertices(std::span<const Vec3f> p) {
  if (p.size() < 3) return std::nullopt;
  std::size_t b = 0, c = 0;
  double far = 0, wide = 0;
  for (std::size_t i = 1; i < p.size(); ++i)
    if (const double d = length(toDouble(p[i]) - toDouble(p[0])); d > far) far = d, b = i;
  const Vec3d ab = toDouble(p[b]) - toDouble(p[0]);
  for (std::size_t i = 1; i < p.size(); ++i)
    if (const double d = length(cross(ab, toDouble(p[i]) - toDouble(p[0]))); d > wide)
      wide = d, c = i;
  // Nearly collinear vertices give a frame that turns with rounding noise.
  if (!(far > 0) || !(wide > 1e-6 * far * far)) return std::nullopt;
  return std::array{std::size_t{0}, b, c};
}

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
  return (h ^ v) * 0x100000001b3ull + (h >> 29);
}

// What two placements of one mesh share exactly: counts, material, triangles, colours.
std::uint64_t signature(const Model& model, std::size_t o) {
  const ObjectRecord& r = model.objects[o];
  std::uint64_t h =
      mix(mix(mix(0xcbf29ce484222325ull, r.vertexCount), r.triangleCount), r.material);
  for (const std::uint32_t i : model.objectIndices(o)) h = mix(h, i);
  if (model.hasColors())
    for (std::uint64_t v = r.vertexOffset; v < r.vertexOffset + r.vertexCount; ++v) {
      const Rgba8 c = model.colors[v];
      h = mix(h, (std::uint64_t{c.r} << 24) | (std::uint64_t{c.g} << 16) |
                     (std::uint64_t{c.b} << 8) | c.a);
    }
  return h;
}

bool sameTrianglesAndColours(const Model& model, std::size_t a, std::size_t b) {
  const ObjectRecord &ra = model.objects[a], &rb = model.objects[b];
  if (ra.vertexCount != rb.vertexCount || ra.triangleCount != rb.triangleCount ||
      ra.material != rb.material)
    return false;
  const auto ia = model.objectIndices(a), ib = model.objectIndices(b);
  if (!std::equal(ia.begin(), ia.end(), ib.begin())) return false;
  if (!model.hasColors()) return true;
  const auto ca = std::span(model.colors).subspan(ra.vertexOffset, ra.vertexCount);
  const auto cb = std::span(model.colors).subspan(rb.vertexOffset, rb.vertexCount);
  return std::equal(ca.begin(), ca.end(), cb.begin());
}

bool normalsFollow(const Model& model, std::size_t a, std::size_t b, const Mat4d& motion) {
  if (!model.hasNormals()) return true;
  const ObjectRecord &ra = model.objects[a], &rb = model.objects[b];
  for (std::uint64_t v = 0; v < ra.vertexCount; ++v) {
    const Vec3d moved = motion.transformVector(toDouble(model.normals[ra.vertexOffset + v]));
    if (!(length(moved - toDouble(model.normals[rb.vertexOffset + v])) <= 1e-3)) return false;
  }
  return true;
}

double diagonal(std::span<const Vec3f> p) {
  Aabbd box;
  for (const Vec3f& v : p) box.add(toDouble(v));
  return length(box.size());
}

}  // namespace

std::optional<Mat4d> fitRigidMotion(std::span<const Vec3f> from, std::span<const Vec3f> to,
                                    double tolerance) {
  if (from.size() != to.size()) return std::nullopt;
  const auto picked = spanningVertices(from);
  if (!picked) return std::nullopt;
  const auto [a, b, c] = *picked;
  const auto source = frameOf(toDouble(from[a]), toDouble(from[b]), toDouble(from[c]));
  const auto target = frameOf(toDouble(to[a]), toDouble(to[b]), toDouble(to[c]));
  if (!source || !target) return std::nullopt;
  // R = T Sᵀ with S, T the frames as columns; both right-handed, so R never mirrors.
  Mat4d motion;
  const Vec3d s[3] = {source->u, source->v, source->w}, t[3] = {target->u, target->v, target->w};
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col)
      motion.at(row, col) = t[0][row] * s[0][col] + t[1][row] * s[1][col] + t[2][row] * s[2][col];
  // The translation through the centroids spreads the rounding over all vertices.
  Vec3d fromCentre, toCentre;
  for (std::size_t i = 0; i < from.size(); ++i) {
    fromCentre += toDouble(from[i]);
    toCentre += toDouble(to[i]);
  }
  const double n = static_cast<double>(from.size());
  const Vec3d shift = toCentre / n - motion.transformVector(fromCentre / n);
  for (int row = 0; row < 3; ++row) motion.at(row, 3) = shift[row];
  for (std::size_t i = 0; i < from.size(); ++i)
    if (!(length(motion.transformPoint(toDouble(from[i])) - toDouble(to[i])) <= tolerance))
      return std::nullopt;  // NaN fails too
  return motion;
}

std::vector<Placement> findPlacements(const Model& model, double relativeTolerance,
                                      std::size_t candidates) {
  std::vector<Placement> placements(model.objectCount());
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> meshes;  // signature → sources
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    placements[o].source = static_cast<std::uint32_t>(o);
    if (model.objects[o].triangleCount == 0) continue;
    const std::span<const Vec3f> positions = model.objectPositions(o);
    std::vector<std::uint32_t>& sources = meshes[signature(model, o)];
    if (sources.empty()) {  // the first of its kind: nothing to fit, no tolerance needed
      if (candidates > 0) sources.push_back(static_cast<std::uint32_t>(o));
      continue;
    }
    // Float positions round with their distance from the origin, not with the part's size.
    double far = 0;
    for (const Vec3f& p : positions) far = std::max(far, length(toDouble(p)));
    const double tolerance = std::max(relativeTolerance * diagonal(positions), 4 * 0x1p-24 * far);
    for (const std::uint32_t s : sources) {
      if (!sameTrianglesAndColours(model, s, o)) continue;
      const auto motion = fitRigidMotion(model.objectPositions(s), positions, tolerance);
      if (!motion || !normalsFollow(model, s, o, *motion)) continue;
      placements[o] = {s, *motion};
      break;
    }
    if (placements[o].source == o && sources.size() < candidates)
      sources.push_back(static_cast<std::uint32_t>(o));
  }
  return placements;
}

}  // namespace lodforge
