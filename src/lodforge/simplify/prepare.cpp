#include "lodforge/simplify/prepare.h"

#include <cassert>

#include "lodforge/core/mesh.h"

namespace lodforge {

PreparedObject prepareObject(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                             std::span<const Rgba8> colors, std::span<const std::uint32_t> indices,
                             const PrepareOptions& options) {
  assert(normals.empty() || normals.size() == positions.size());
  assert(colors.empty() || colors.size() == positions.size());
  PreparedObject out;
  // Weld bit-identical positions, whatever their attributes (docs/simplify.md: attribute seams).
  std::vector<std::uint32_t> remap(positions.size());
  const std::uint32_t welded = weldVertices(positions, {}, {}, WeldOptions{}, remap);
  std::vector<Vec3f> weldedPositions(welded);
  remapVertexAttribute(positions, remap, std::span(weldedPositions));
  std::vector<std::uint32_t> weldedIndices(indices.begin(), indices.end());
  remapIndices(weldedIndices, remap);
  weldedIndices.resize(
      3 * removeDegenerateTriangles(weldedPositions, weldedIndices, {.zeroArea = false}));

  // Seam normals average; the first colour at a position wins.
  std::vector<Vec3f> weldedNormals;
  if (!normals.empty()) {
    weldedNormals.assign(welded, Vec3f{});
    for (std::size_t v = 0; v < positions.size(); ++v) weldedNormals[remap[v]] += normals[v];
  }
  std::vector<Rgba8> weldedColors;
  if (!colors.empty()) {
    weldedColors.resize(welded);
    remapVertexAttribute(colors, remap, std::span(weldedColors));
  }

  // Drop vertices no triangle uses.
  std::vector<std::uint32_t> keep(welded);
  const std::uint32_t kept = findReferencedVertices(welded, weldedIndices, keep);
  out.positions.resize(kept);
  compactVertexAttribute<Vec3f>(weldedPositions, keep, out.positions);
  if (!weldedColors.empty()) {
    out.colors.resize(kept);
    compactVertexAttribute<Rgba8>(weldedColors, keep, out.colors);
  }
  out.indices = std::move(weldedIndices);
  remapIndices(out.indices, keep);
  if (!weldedNormals.empty()) {
    out.normals.resize(kept);
    compactVertexAttribute<Vec3f>(weldedNormals, keep, out.normals);
    for (Vec3f& n : out.normals) n = normalizeOr(n, Vec3f{});
  }
  if (options.normals) {
    // Positions without a usable normal (none given, or opposite normals cancelling out) get
    // the area-weighted face normal.
    std::vector<Vec3f> computed(kept);
    computeVertexNormals(out.positions, out.indices, computed);
    if (out.normals.empty()) out.normals = std::move(computed);
    for (std::size_t v = 0; v < kept; ++v) {
      if (out.normals[v] == Vec3f{}) out.normals[v] = computed[v];
    }
  }
  return out;
}

}  // namespace lodforge
