#include "lodforge/simplify/shape_cache.h"

namespace lodforge {
namespace {

MeshView viewOf(const SourceObject& object) {
  return {object.positions, object.normals, object.colors, object.indices, object.material};
}

// What a built mesh holds per vertex and per triangle once the permutations are dropped.
std::uint64_t meshBytes(std::uint64_t vertices, std::uint64_t triangles) {
  return vertices * (12 + 12 + 4 + 4 + 4 + 4) + triangles * 12;
}

// Everything of a progressive mesh but where its vertices are: what every placement shares. The
// permutations are left out (only the build that made the mesh uses them).
ProgressiveMesh levelsOf(const ProgressiveMesh& mesh) {
  ProgressiveMesh levels;
  levels.q = mesh.q;
  levels.colors = mesh.colors;
  levels.uvs = mesh.uvs;
  levels.whole = mesh.whole;
  levels.triangles = mesh.triangles;
  levels.ecol = mesh.ecol;
  levels.map = mesh.map;
  levels.error = mesh.error;
  return levels;
}

}  // namespace

ShapeCache::ShapeCache(std::uint64_t bytes, double relativeTolerance, std::size_t candidates)
    : capacity_(bytes), relativeTolerance_(relativeTolerance), index_(candidates) {}

ShapeLookup ShapeCache::lookup(const SourceObject& object) {
  ShapeLookup result;
  if (object.indices.empty() || capacity_ == 0) return result;
  const MeshView mesh = viewOf(object);
  const PlacementKey key = placementKey(mesh, relativeTolerance_);
  const auto kept = [this](std::uint32_t s) { return viewOf(shapes_[s].input); };
  if (const auto found = index_.find(key, mesh, kept)) {
    result.placed = ShapeMatch{found->source, found->motion};
    return result;
  }
  const std::uint64_t need =
      object.memoryBytes() + meshBytes(object.positions.size(), object.indices.size() / 3);
  const auto id = static_cast<std::uint32_t>(shapes_.size());
  if (bytes_ + need > capacity_ || !index_.add(key, id)) return result;
  Shape shape;
  shape.input.positions = object.positions;
  shape.input.normals = object.normals;
  shape.input.colors = object.colors;
  shape.input.indices = object.indices;
  shape.input.material = object.material;
  shapes_.push_back(std::move(shape));
  bytes_ += need;
  result.remembered = id;
  return result;
}

void ShapeCache::setMesh(std::uint32_t shape, const ProgressiveMesh& mesh) {
  Shape& kept = shapes_[shape];
  kept.mesh = levelsOf(mesh);
  kept.mesh.positions = mesh.positions;
  kept.mesh.normals = mesh.normals;
  kept.built = true;
}

ProgressiveMesh placedMesh(const ProgressiveMesh& mesh, const Mat4d& motion) {
  ProgressiveMesh placed = levelsOf(mesh);
  placed.positions.reserve(mesh.positions.size());
  for (const Vec3f& p : mesh.positions)
    placed.positions.push_back(toFloat(motion.transformPoint(toDouble(p))));
  placed.normals.reserve(mesh.normals.size());
  for (const Vec3f& n : mesh.normals)
    placed.normals.push_back(toFloat(motion.transformVector(toDouble(n))));
  return placed;
}

}  // namespace lodforge
