#include "lodforge/simplify/extract.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "lodforge/simplify/progressive.h"
#include "lodforge/simplify/reform.h"

namespace lodforge {

std::vector<std::uint32_t> vertexCountsForRatio(const Package& package, double ratio) {
  std::vector<std::uint32_t> counts(package.objectCount());
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const PackageObject& o = package.object(i);
    const auto wanted =
        static_cast<std::uint32_t>(std::llround(std::clamp(ratio, 0.0, 1.0) * o.vertexCount));
    counts[i] = package.wholeAt(i, std::clamp(wanted, o.minVertexCount, o.vertexCount));
  }
  return counts;
}

std::vector<std::uint32_t> vertexCountsForError(const Package& package, double error) {
  std::vector<std::uint32_t> counts(package.objectCount());
  for (std::size_t i = 0; i < counts.size(); ++i) {
    // Whole already in a package lodforge wrote (the error is flat between whole counts); a
    // forged table is rounded down all the same.
    counts[i] = package.wholeAt(
        i, vertexCountForError(package.error(i), package.object(i).minVertexCount, error));
  }
  return counts;
}

Model extractModel(const Package& package, std::span<const std::uint32_t> vertexCounts) {
  const std::size_t objects = package.objectCount();
  assert(vertexCounts.size() == objects);
  // The selection: every object, with prefix sums of its triangles and vertices.
  std::vector<std::uint32_t> ids(objects), bases(objects);
  std::vector<std::uint64_t> starts(objects + 1, 0);
  std::uint64_t vertexTotal = 0;
  for (std::size_t i = 0; i < objects; ++i) {
    ids[i] = static_cast<std::uint32_t>(i);
    bases[i] = 0;  // object-local indices: the Model keeps them per object
    assert(package.wholeAt(i, vertexCounts[i]) == vertexCounts[i]);
    starts[i + 1] = starts[i] + package.trianglesAt(i, vertexCounts[i]);
    vertexTotal += vertexCounts[i];
  }
  Model model;
  model.origin = package.origin();
  for (std::size_t m = 0; m < package.materialCount(); ++m)
    model.materials.push_back(package.material(m));
  for (std::size_t l = 0; l < package.layerCount(); ++l)
    model.layers.emplace_back(package.layer(l));
  for (std::size_t k = 0; k < package.imageCount(); ++k) model.images.push_back(package.image(k));
  model.indices.resize(3 * starts[objects]);
  reformSelection(ReformSource::of(package), {ids, vertexCounts, starts, bases}, model.indices);

  model.positions.reserve(vertexTotal);
  if (package.header().hasNormals()) model.normals.reserve(vertexTotal);
  if (package.header().hasColors()) model.colors.reserve(vertexTotal);
  if (package.header().hasUvs()) model.uvs.reserve(vertexTotal);
  // The triangles are already in place (object after object); add each object's vertices and
  // its record.
  for (std::size_t i = 0; i < objects; ++i) {
    const std::uint32_t n = vertexCounts[i];
    const auto positions = package.positions(i).first(n);
    ObjectRecord record;
    record.vertexOffset = model.positions.size();
    record.triangleOffset = starts[i];
    record.vertexCount = n;
    record.triangleCount = static_cast<std::uint32_t>(starts[i + 1] - starts[i]);
    record.nameOffset = model.names.size();
    record.nameLength = static_cast<std::uint32_t>(package.objectName(i).size());
    model.names.append(package.objectName(i));
    record.pathOffset = model.paths.size();
    record.pathLength = static_cast<std::uint32_t>(package.objectPath(i).size());
    model.paths.append(package.objectPath(i));
    record.material = package.objectMaterial(i);
    record.layer = package.objectLayerIndex(i);
    model.positions.insert(model.positions.end(), positions.begin(), positions.end());
    if (package.header().hasNormals()) {
      const auto normals = package.normals(i).first(n);
      model.normals.insert(model.normals.end(), normals.begin(), normals.end());
    }
    if (package.header().hasColors()) {
      const auto colors = package.colors(i).first(n);
      model.colors.insert(model.colors.end(), colors.begin(), colors.end());
    }
    if (package.header().hasUvs()) {
      const auto uvs = package.uvs(i).first(n);
      model.uvs.insert(model.uvs.end(), uvs.begin(), uvs.end());
    }
    Aabb box;
    for (const Vec3f& p : positions) box.add(p);
    record.bounds = box;
    model.objects.push_back(record);
  }
  return model;
}

}  // namespace lodforge
