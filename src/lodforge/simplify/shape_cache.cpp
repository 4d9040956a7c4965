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
  shapes_[shape].built = true;
  ProgressiveMesh& kept = shapes_[shape].mesh;
  kept.q = mesh.q;
  kept.positions = mesh.positions;
  kept.normals = mesh.normals;
  kept.colors = mesh.colors;
  kept.triangles = mesh.triangles;
  kept.ecol = mesh.ecol;
  kept.map = mesh.map;
  kept.error = mesh.error;
}

ProgressiveMesh placedMesh(const ProgressiveMesh& mesh, const Mat4d& motion) {
  ProgressiveMesh placed;
  placed.q = mesh.q;
  placed.positions.reserve(mesh.positions.size());
  for (const Vec3f& p : mesh.positions)
    placed.positions.push_back(toFloat(motion.transformPoint(toDouble(p))));
  placed.normals.reserve(mesh.normals.size());
  for (const Vec3f& n : mesh.normals)
    placed.normals.push_back(toFloat(motion.transformVector(toDouble(n))));
  placed.colors = mesh.colors;
  placed.triangles = mesh.triangles;
  placed.ecol = mesh.ecol;
  placed.map = mesh.map;
  placed.error = mesh.error;
  return placed;
}

}  // namespace lodforge
