#include "lodforge/simplify/simplify_model.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <vector>

#include "lodforge/core/mesh.h"
#include "lodforge/simplify/progressive.h"

namespace lodforge {
namespace {

// One object's surface: a vertex per position, with its triangles' wedges.
struct Surface {
  std::vector<Vec3f> positions;
  WedgeSurface triangles;
};

Surface surfaceOf(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices) {
  std::vector<std::uint32_t> remap(positions.size());
  const std::uint32_t count = weldVertices(positions, {}, {}, {}, remap);
  Surface s;
  s.positions.resize(count);
  remapVertexAttribute(positions, remap, std::span(s.positions));
  s.triangles = wedgeSurface(remap, indices);
  return s;
}

// Appends object `o` of `in` to `out` with the triangles `simplified` left over its wedges: a
// vertex per wedge still used, in order of first use, with every attribute it had.
void appendSimplified(const Model& in, std::size_t o, const SimplifiedMesh& simplified,
                      ModelBuilder& builder, Model& out) {
  const ObjectRecord& object = in.objects[o];
  builder.beginObject(in.objectName(o), in.objectPath(o));
  std::vector<std::uint32_t> local(object.vertexCount, ~0u);
  std::vector<std::uint32_t> corners(simplified.wedges.size());
  for (std::size_t i = 0; i < simplified.wedges.size(); ++i) {
    const std::uint32_t w = simplified.wedges[i];
    if (local[w] == ~0u) {
      const std::uint64_t v = object.vertexOffset + w;
      local[w] = builder.addVertex(in.positions[v]);
      if (in.hasNormals()) out.normals.push_back(in.normals[v]);
      if (in.hasColors()) out.colors.push_back(in.colors[v]);
      if (in.hasUvs()) out.uvs.push_back(in.uvs[v]);
    }
    corners[i] = local[w];
  }
  for (std::size_t i = 0; i < corners.size(); i += 3)
    builder.addTriangle(corners[i], corners[i + 1], corners[i + 2]);
  builder.endObject();
  out.objects.back().material = object.material;
  out.objects.back().layer = object.layer;
}

}  // namespace

WedgeSurface wedgeSurface(std::span<const std::uint32_t> pointOf,
                          std::span<const std::uint32_t> indices) {
  WedgeSurface out;
  for (std::size_t t = 0; t < indices.size(); t += 3) {
    const std::array<std::uint32_t, 3> c = {pointOf[indices[t]], pointOf[indices[t + 1]],
                                            pointOf[indices[t + 2]]};
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) continue;
    out.indices.insert(out.indices.end(), c.begin(), c.end());
    out.wedges.insert(out.wedges.end(), indices.begin() + static_cast<std::ptrdiff_t>(t),
                      indices.begin() + static_cast<std::ptrdiff_t>(t + 3));
  }
  return out;
}

ModelSimplifyStats simplifyModel(Model& model, double ratio) {
  assert(ratio >= 0 && ratio <= 1);
  ModelSimplifyStats stats;
  stats.trianglesBefore = model.triangleCount();
  Model out;
  out.origin = model.origin;
  out.materials = model.materials;
  out.images = model.images;
  out.layers = model.layers;
  ModelBuilder builder(out);
  for (std::size_t o = 0; o < model.objectCount(); ++o) {
    const std::span<const Vec3f> positions = model.objectPositions(o);
    const Surface surface = surfaceOf(positions, model.objectIndices(o));
    // Coordinates of the object's wedges (none: all zero, and the texture term is zero).
    std::vector<Vec2f> uvs(positions.size());
    if (model.hasUvs())
      std::copy_n(model.uvs.begin() + static_cast<std::ptrdiff_t>(model.objects[o].vertexOffset),
                  positions.size(), uvs.begin());
    ProgressiveOptions options;
    options.collapseBorders = true;
    options.stopAtTriangles = static_cast<std::uint32_t>(
        std::max(1.0, std::floor(ratio * static_cast<double>(model.objects[o].triangleCount))));
    options.wedges = surface.triangles.wedges;
    options.wedgeUvs = uvs;
    const SimplifiedMesh simplified =
        surface.triangles.indices.empty()
            ? SimplifiedMesh{}
            : simplifyMesh(surface.positions, surface.triangles.indices, options);
    stats.error = std::max(stats.error, static_cast<double>(simplified.error));
    appendSimplified(model, o, simplified, builder, out);
  }
  stats.trianglesAfter = out.triangleCount();
  model = std::move(out);
  return stats;
}

}  // namespace lodforge
