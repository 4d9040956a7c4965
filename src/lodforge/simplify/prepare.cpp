#include "lodforge/simplify/prepare.h"

#include <cassert>

#include "lodforge/core/mesh.h"
#include "lodforge/simplify/simplify_model.h"

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

namespace {

// The wedges: input vertices welded where position, coordinates, normal and colour all agree.
struct Wedges {
  std::vector<std::uint32_t> remap;  // input vertex -> wedge
  std::uint32_t count = 0;
};

Wedges weldWedges(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                  std::span<const Rgba8> colors, std::span<const Vec2f> uvs) {
  Wedges w;
  w.remap.resize(positions.size());
  w.count = weldVertices(positions, normals, colors,
                         {.keepNormalSplits = !normals.empty(),
                          .normalAngleDegrees = 0.5f,
                          .keepColorSplits = !colors.empty()},
                         w.remap, uvs);
  return w;
}

template <class T>
std::vector<T> gather(std::span<const T> in, std::span<const std::uint32_t> remap,
                      std::uint32_t count) {
  std::vector<T> out(count);
  compactVertexAttribute<T>(in, remap, out);
  return out;
}

}  // namespace

PreparedTexturedObject prepareTexturedObject(std::span<const Vec3f> positions,
                                             std::span<const Vec3f> normals,
                                             std::span<const Rgba8> colors,
                                             std::span<const Vec2f> uvs,
                                             std::span<const std::uint32_t> indices) {
  assert(uvs.size() == positions.size());
  PreparedTexturedObject out;
  // Points: bit-identical positions welded, whatever their attributes.
  std::vector<std::uint32_t> pointOf(positions.size());
  const std::uint32_t pointCount = weldVertices(positions, {}, {}, WeldOptions{}, pointOf);
  const Wedges wedges = weldWedges(positions, normals, colors, uvs);
  // Triangles over points, corners naming wedges; those with a repeated point have no area.
  std::vector<std::uint32_t> wedgeIndices(indices.begin(), indices.end());
  remapIndices(wedgeIndices, wedges.remap);
  std::vector<std::uint32_t> wedgePoint(wedges.count);
  for (std::size_t v = 0; v < positions.size(); ++v) wedgePoint[wedges.remap[v]] = pointOf[v];
  WedgeSurface surface = wedgeSurface(wedgePoint, wedgeIndices);
  out.indices = std::move(surface.indices);
  out.wedges = std::move(surface.wedges);
  // Only what the triangles use, points and wedges each in order of first index.
  std::vector<std::uint32_t> keepPoint(pointCount), keepWedge(wedges.count);
  const std::uint32_t points = findReferencedVertices(pointCount, out.indices, keepPoint);
  const std::uint32_t kept = findReferencedVertices(wedges.count, out.wedges, keepWedge);
  std::vector<Vec3f> pointPositions(pointCount);
  remapVertexAttribute(positions, pointOf, std::span(pointPositions));
  out.points.resize(points);
  compactVertexAttribute<Vec3f>(pointPositions, keepPoint, out.points);
  remapIndices(out.indices, keepPoint);
  remapIndices(out.wedges, keepWedge);
  std::vector<std::uint32_t> inputToWedge(positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) inputToWedge[v] = keepWedge[wedges.remap[v]];
  out.uvs = gather(uvs, inputToWedge, kept);
  if (!colors.empty()) out.colors = gather(colors, inputToWedge, kept);
  if (!normals.empty()) {
    out.normals = gather(normals, inputToWedge, kept);
    for (Vec3f& n : out.normals) n = normalizeOr(n, Vec3f{0, 0, 1});
  } else {
    std::vector<Vec3f> pointNormals(points);
    computeVertexNormals(out.points, out.indices, pointNormals);
    out.normals.resize(kept);
    for (std::size_t c = 0; c < out.wedges.size(); ++c)
      out.normals[out.wedges[c]] = pointNormals[out.indices[c]];
  }
  return out;
}

}  // namespace lodforge
