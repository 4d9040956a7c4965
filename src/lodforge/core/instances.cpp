#include "lodforge/core/instances.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>
#include <unordered_map>

#include <Eigen/Geometry>

namespace lodforge {
namespace {

// Whether the vertices stand off a line through the first and the farthest from it.
bool spansAPlane(std::span<const Vec3f> p) {
  if (p.size() < 3) return false;
  std::size_t b = 0;
  double far = 0, wide = 0;
  for (std::size_t i = 1; i < p.size(); ++i)
    if (const double d = length(toDouble(p[i]) - toDouble(p[0])); d > far) far = d, b = i;
  const Vec3d ab = toDouble(p[b]) - toDouble(p[0]);
  for (std::size_t i = 1; i < p.size(); ++i)
    wide = std::max(wide, length(cross(ab, toDouble(p[i]) - toDouble(p[0]))));
  return far > 0 && wide > 1e-6 * far * far;
}

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
  return (h ^ v) * 0x100000001b3ull + (h >> 29);
}

double diagonal(std::span<const Vec3f> p) {
  Aabbd box;
  for (const Vec3f& v : p) box.add(toDouble(v));
  return length(box.size());
}

}  // namespace

std::optional<Mat4d> fitRigidMotion(std::span<const Vec3f> from, std::span<const Vec3f> to,
                                    double tolerance) {
  // Nearly collinear vertices leave the turn about their line undetermined: no motion.
  if (from.size() != to.size() || !spansAPlane(from)) return std::nullopt;
  // The least-squares rotation (Kabsch, through Umeyama's SVD with the sign fixed, so it never
  // mirrors): every vertex weighs in, so float rounding of a thin part does not tilt it as a
  // frame of three vertices would.
  Eigen::Matrix3Xd a(3, from.size()), b(3, to.size());
  for (std::size_t i = 0; i < from.size(); ++i) {
    const auto column = static_cast<Eigen::Index>(i);
    a.col(column) << from[i][0], from[i][1], from[i][2];
    b.col(column) << to[i][0], to[i][1], to[i][2];
  }
  const Eigen::Matrix4d fit = Eigen::umeyama(a, b, false);
  Mat4d motion;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col) motion.at(row, col) = fit(row, col);
  for (std::size_t i = 0; i < from.size(); ++i)
    if (!(length(motion.transformPoint(toDouble(from[i])) - toDouble(to[i])) <= tolerance))
      return std::nullopt;  // NaN fails too
  return motion;
}

PlacementKey placementKey(const MeshView& mesh, double relativeTolerance) {
  PlacementKey key;
  std::uint64_t h = mix(mix(mix(0xcbf29ce484222325ull, mesh.positions.size()), mesh.indices.size()),
                        mesh.material);
  for (const std::uint32_t i : mesh.indices) h = mix(h, i);
  for (const Rgba8 c : mesh.colors)
    h = mix(h, (std::uint64_t{c.r} << 24) | (std::uint64_t{c.g} << 16) | (std::uint64_t{c.b} << 8) |
                   c.a);
  for (const Vec2f uv : mesh.uvs)
    h = mix(mix(h, std::bit_cast<std::uint32_t>(uv.x)), std::bit_cast<std::uint32_t>(uv.y));
  key.signature = h;
  if (mesh.positions.empty()) return key;
  Vec3d centre;
  double far = 0;
  for (const Vec3f& p : mesh.positions) {
    centre += toDouble(p);
    // Float positions round with their distance from the origin, not with the part's size.
    far = std::max(far, length(toDouble(p)));
  }
  centre = centre / static_cast<double>(mesh.positions.size());
  double squares = 0;
  for (const Vec3f& p : mesh.positions) squares += dot(toDouble(p) - centre, toDouble(p) - centre);
  key.spread = std::sqrt(squares / static_cast<double>(mesh.positions.size()));
  // Both meshes round (up to half an ulp, 2⁻²⁴·|x|, per coordinate each) and the fit spreads
  // that: eight times 2⁻²⁴ of the distance from the origin.
  key.tolerance = std::max(relativeTolerance * diagonal(mesh.positions), 8 * 0x1p-24 * far);
  key.fittable =
      std::isfinite(key.spread) && std::isfinite(key.tolerance) && spansAPlane(mesh.positions);
  return key;
}

std::optional<Mat4d> placementOf(const MeshView& source, const MeshView& mesh, double tolerance) {
  if (source.material != mesh.material || !std::ranges::equal(source.indices, mesh.indices) ||
      !std::ranges::equal(source.colors, mesh.colors) ||
      !std::ranges::equal(source.uvs, mesh.uvs) || source.normals.size() != mesh.normals.size())
    return std::nullopt;
  const auto motion = fitRigidMotion(source.positions, mesh.positions, tolerance);
  if (!motion) return std::nullopt;
  for (std::size_t v = 0; v < source.normals.size(); ++v) {
    const Vec3d moved = motion->transformVector(toDouble(source.normals[v]));
    if (!(length(moved - toDouble(mesh.normals[v])) <= 1e-3)) return std::nullopt;
  }
  return motion;
}

std::optional<FoundPlacement> PlacementIndex::find(
    const PlacementKey& key, const MeshView& mesh,
    const std::function<MeshView(std::uint32_t)>& kept) const {
  const auto meshes = meshes_.find(key.signature);
  if (!key.fittable || meshes == meshes_.end()) return std::nullopt;
  // A rigid copy's vertices lie within the tolerance, which moves the centroid and the spread by
  // at most as much each; the kept mesh may lie farther from the origin and round more.
  const auto& bySpread = meshes->second.bySpread;
  const double window = 2 * std::max(key.tolerance, meshes->second.widest);
  struct Candidate {
    double difference, tolerance;
    std::uint32_t id;
  };
  std::vector<Candidate> near;
  for (auto at = bySpread.lower_bound(key.spread - window);
       at != bySpread.end() && at->first <= key.spread + window; ++at) {
    const auto [id, keptTolerance] = at->second;
    const double tolerance = std::max(key.tolerance, keptTolerance);
    if (const double difference = std::abs(at->first - key.spread); difference <= 2 * tolerance)
      near.push_back({difference, tolerance, id});
  }
  // Nearest spread first (ties by id, the earlier kept), so the cap drops the least likely.
  std::sort(near.begin(), near.end(), [](const Candidate& a, const Candidate& b) {
    return a.difference != b.difference ? a.difference < b.difference : a.id < b.id;
  });
  if (near.size() > candidates_) near.resize(candidates_);
  for (const Candidate& candidate : near)
    if (const auto motion = placementOf(kept(candidate.id), mesh, candidate.tolerance))
      return FoundPlacement{candidate.id, *motion};
  return std::nullopt;
}

bool PlacementIndex::add(const PlacementKey& key, std::uint32_t id) {
  if (!key.fittable) return false;
  Kept& meshes = meshes_[key.signature];
  const double window = 2 * key.tolerance;
  const auto first = meshes.bySpread.lower_bound(key.spread - window);
  const auto last = meshes.bySpread.upper_bound(key.spread + window);
  if (static_cast<std::size_t>(std::distance(first, last)) >= candidates_) return false;
  meshes.bySpread.emplace(key.spread, std::pair{id, key.tolerance});
  meshes.widest = std::max(meshes.widest, key.tolerance);
  return true;
}

std::vector<Placement> findPlacements(const Model& model, double relativeTolerance,
                                      std::size_t candidates) {
  const auto view = [&](std::uint32_t o) {
    const ObjectRecord& r = model.objects[o];
    MeshView mesh{model.objectPositions(o), {}, {}, model.objectIndices(o), r.material};
    if (model.hasNormals())
      mesh.normals = std::span(model.normals).subspan(r.vertexOffset, r.vertexCount);
    if (model.hasColors())
      mesh.colors = std::span(model.colors).subspan(r.vertexOffset, r.vertexCount);
    if (model.hasUvs()) mesh.uvs = std::span(model.uvs).subspan(r.vertexOffset, r.vertexCount);
    return mesh;
  };
  std::vector<Placement> placements(model.objectCount());
  PlacementIndex index(candidates);
  for (std::uint32_t o = 0; o < model.objectCount(); ++o) {
    placements[o].source = o;
    if (model.objects[o].triangleCount == 0) continue;
    const MeshView mesh = view(o);
    const PlacementKey key = placementKey(mesh, relativeTolerance);
    if (const auto found = index.find(key, mesh, view))
      placements[o] = {found->source, found->motion};
    else
      index.add(key, o);
  }
  return placements;
}

}  // namespace lodforge
