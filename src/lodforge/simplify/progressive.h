// Progressive meshes as in Peng & Cao, "Parallel LOD for CAD model rendering" §3.1: half-edge
// collapses (a vertex merges into an existing neighbour; no new vertices) in order of cost down
// to the simplest version, recorded as ECol / PermuteV / PermuteT / Map, with vertices and
// triangles rearranged (Algorithm 1) so that the first n vertices and the first map(n)
// triangles are the mesh after p - n collapses (once re-formed, Algorithm 2 in reform.h).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/math.h"

namespace lodforge {

enum class CollapseCost : std::uint8_t {
  kQuadric,  // Garland–Heckbert quadric error evaluated at the target (area-weighted planes)
  kMelax,    // Melax's edge length x curvature cost, the paper's choice
};

enum class CollapseDirection : std::uint8_t {
  // Eq. 1 for boundary vertices (they never move); an interior edge collapses whichever way is
  // cheaper. Vertex indices carry no geometric meaning, so Eq. 1's index order is not used.
  kCheaper,
  // Eq. 1 literally: edge (a, b) with a < b collapses a into b unless a is a boundary vertex.
  kPaper,
};

struct ProgressiveOptions {
  CollapseCost cost = CollapseCost::kQuadric;
  CollapseDirection direction = CollapseDirection::kCheaper;
  // A collapse may turn no face by more than this (the cosine of the angle between its normals
  // before and after): 0.25 (~75.5 degrees) stops near-flips; tiles ask for cos 30 degrees.
  double minNormalCos = 0.25;
  // Vertices that must never move, beside the boundary (one flag per vertex, or empty).
  std::span<const std::uint8_t> locked{};
  // Stop once the mesh has at most this many triangles (0: collapse down to the minimum).
  std::uint32_t stopAtTriangles = 0;
  // Refuse a collapse whose vertex error bound (ProgressiveMesh::error) would pass this (model
  // units; 0: no bound), so the result stays within it.
  double maxError = 0;
  // Let boundary vertices collapse along their boundary into a boundary neighbour (quadrics
  // then hold planes along boundary edges, so a rim keeps its shape). Off, as the CAD paper
  // has it: boundary vertices never move. Vertices where a boundary meets itself or a
  // non-manifold edge, and `locked` ones, stay put either way.
  bool collapseBorders = false;
  // Textured meshes: positions are then one vertex per point of the surface,
  // and `wedges` gives each index's wedge (the vertex of the textured mesh it came from: its
  // texture coordinates `wedgeUvs`, material and the rest). A collapse maps each wedge of the
  // vertex that goes to the wedge of its target on the same triangles, so every triangle keeps
  // one chart and a seam moves only along itself; one that cannot (a chart corner) is refused,
  // as is one that flips a triangle in texture space. The texture error joins the cost.
  std::span<const std::uint32_t> wedges{};
  std::span<const Vec2f> wedgeUvs{};
};

// One object after preprocessing. p = vertexCount(), q = the vertices that never collapse (the
// boundary vertices Q of the paper, plus interior vertices no valid collapse could remove).
struct ProgressiveMesh {
  std::uint32_t q = 0;
  std::vector<Vec3f> positions;          // p, rearranged (Algorithm 1)
  std::vector<Vec3f> normals;            // p or empty
  std::vector<Rgba8> colors;             // p or empty
  std::vector<std::uint32_t> triangles;  // 3 per triangle, rearranged, full-detail corners
  // ECol': ecol[i] is the vertex that i collapses into; ecol[i] < i for i >= q (chains strictly
  // decrease), ecol[i] == i for the q vertices that never collapse.
  std::vector<std::uint32_t> ecol;
  std::vector<std::uint32_t>
      map;  // p - q + 1 entries: map[n - q] = triangles of the mesh at n vertices
  // Geometric error of the mesh at n vertices, model units: error[n - q], non-increasing in n,
  // error[p - q] = 0 (the monotone maximum of the per-collapse errors, see docs/simplify.md).
  std::vector<float> error;
  // The permutations of Algorithm 1: original index -> rearranged index (of a wedge when
  // textured; ~0u for a wedge no triangle uses).
  std::vector<std::uint32_t> permuteV, permuteT;
  // Textured meshes (ProgressiveOptions::wedges): the vertices are the wedges, each with its
  // point's position and its own texture coordinates `uvs` (p), and a point's wedges leave
  // together. whole[n - q] is the largest count <= n that leaves no point half collapsed
  // (between, a count re-forms with cracks; map and error there are the whole count's). Both
  // empty otherwise: every count is whole.
  std::vector<Vec2f> uvs;
  std::vector<std::uint32_t> whole;

  std::uint32_t vertexCount() const { return static_cast<std::uint32_t>(positions.size()); }
  std::uint32_t triangleCount() const { return static_cast<std::uint32_t>(triangles.size() / 3); }
  std::uint32_t trianglesAt(std::uint32_t n) const { return map[n - q]; }
  float errorAt(std::uint32_t n) const { return error[n - q]; }
  // The fewest vertices whose error is at most `error` (q if every level qualifies).
  std::uint32_t vertexCountForError(float error) const;
  std::uint32_t wholeAt(std::uint32_t n) const { return whole.empty() ? n : whole[n - q]; }
};

// An error table is non-increasing in the vertex count (entry i belongs to `fewest + i`
// vertices): the fewest vertices whose error is at most `allowed`, `fewest + error.size()` when
// no entry is. One lookup for the builder, `extract --error` and the runtime's selection.
std::uint32_t vertexCountForError(std::span<const float> error, std::uint32_t fewest,
                                  double allowed);

// Builds the progressive mesh of one object. Expects a welded, indexed mesh without repeated
// corners in a triangle and without unreferenced vertices (prepareObject in prepare.h does
// that). `normals` and `colors` may be empty; they are carried along with their vertex. With
// `options.wedges` (prepareTexturedObject) the result is over the wedges, and `normals` and
// `colors` are per wedge (as options.wedgeUvs).
ProgressiveMesh buildProgressive(std::span<const Vec3f> positions,
                                 std::span<const std::uint32_t> indices,
                                 std::span<const Vec3f> normals, std::span<const Rgba8> colors,
                                 const ProgressiveOptions& options = {});

// One simplified version of a mesh, by the same collapses: the kept input vertices and the
// triangles over them (indices into `vertices`), and the recorded error of that level.
struct SimplifiedMesh {
  std::vector<std::uint32_t> vertices;  // input index of each kept vertex
  std::vector<std::uint32_t> indices;   // 3 per triangle, < vertices.size()
  float error = 0;                      // model units, as in ProgressiveMesh::error
  std::vector<std::uint8_t> border;     // per kept vertex: on a boundary or non-manifold edge
  // Per input vertex: the kept vertex (index into `vertices`) it was collapsed into, through
  // however many collapses; ~0u if that vertex is left in no triangle.
  std::vector<std::uint32_t> representative;
  // With ProgressiveOptions::wedges: the input wedge of each corner of `indices`.
  std::vector<std::uint32_t> wedges;
};

// Collapses until at most `options.stopAtTriangles` triangles remain or nothing more may
// collapse (borders, `options.locked`, the normal limit), and returns that mesh.
SimplifiedMesh simplifyMesh(std::span<const Vec3f> positions,
                            std::span<const std::uint32_t> indices,
                            const ProgressiveOptions& options);

// Memory buildProgressive needs for a mesh of this size (for memory budgets).
std::uint64_t progressiveBuildBytes(std::uint64_t vertices, std::uint64_t triangles);

}  // namespace lodforge
