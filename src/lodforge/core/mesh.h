// Mesh kernels over plain arrays. Each works on one indexed triangle list (positions plus
// 3 indices per triangle) and writes into caller-sized output, so it runs the same on a
// std::vector, a slice of a Model, or an mmap'd file.
#pragma once

#include <cstdint>
#include <span>

#include "lodforge/core/math.h"

namespace lodforge {

Aabb computeBounds(std::span<const Vec3f> positions);

struct WeldOptions {
  // 0 welds bit-identical positions (with -0 == +0); > 0 welds positions within this distance.
  float epsilon = 0.0f;
  // Keep vertices apart whose normals differ by more than `normalAngleDegrees` (crease splits).
  bool keepNormalSplits = false;
  float normalAngleDegrees = 1.0f;
  // Keep vertices apart whose colours differ.
  bool keepColorSplits = false;
};

// Finds vertices that can be merged. Writes remap[v] = new index of vertex v (dense, in order of
// first occurrence) and returns the new vertex count. `normals` and `colors` may be empty; they
// are consulted only when the options ask to keep their splits. Vertices whose texture
// coordinates (`uvs`, empty or one per vertex) differ always stay apart: a UV seam is two
// vertices. Deterministic: a vertex merges into the earliest earlier representative it matches.
std::uint32_t weldVertices(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                           std::span<const Rgba8> colors, const WeldOptions& options,
                           std::span<std::uint32_t> remap, std::span<const Vec2f> uvs = {});

// out[remap[v]] = in[v] for every v (the representative's value wins: it is written last when
// scanning backwards). `out` has the new vertex count.
template <class T>
void remapVertexAttribute(std::span<const T> in, std::span<const std::uint32_t> remap,
                          std::span<T> out) {
  for (std::size_t v = in.size(); v-- > 0;) out[remap[v]] = in[v];
}

// indices[i] = remap[indices[i]].
void remapIndices(std::span<std::uint32_t> indices, std::span<const std::uint32_t> remap);

struct DegenerateOptions {
  // Also drop triangles whose area is zero (collinear corners), not only repeated indices.
  bool zeroArea = true;
};
// Compacts `indices` in place, dropping degenerate triangles; returns the kept triangle count.
std::size_t removeDegenerateTriangles(std::span<const Vec3f> positions,
                                      std::span<std::uint32_t> indices,
                                      const DegenerateOptions& options = {});

// Area-weighted vertex normals; vertices without area get (0, 0, 1).
void computeVertexNormals(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices,
                          std::span<Vec3f> normals);

// Labels every triangle with its connected component (triangles sharing a vertex are
// connected), numbered in order of first triangle. Returns the component count.
std::uint32_t connectedComponents(std::uint32_t vertexCount, std::span<const std::uint32_t> indices,
                                  std::span<std::uint32_t> triangleComponent);

// Drops vertices no triangle uses: writes remap (~0u for dropped) and returns the kept count.
// Apply with remapIndices and a gather of the kept vertices (compactVertexAttribute).
std::uint32_t findReferencedVertices(std::uint32_t vertexCount,
                                     std::span<const std::uint32_t> indices,
                                     std::span<std::uint32_t> remap);
template <class T>
void compactVertexAttribute(std::span<const T> in, std::span<const std::uint32_t> remap,
                            std::span<T> out) {
  for (std::size_t v = 0; v < in.size(); ++v) {
    if (remap[v] != ~0u) out[remap[v]] = in[v];
  }
}

// Boundary edges: edges used by exactly one triangle (an open mesh's rims and holes).
std::uint64_t countBoundaryEdges(std::span<const std::uint32_t> indices);

}  // namespace lodforge
