// The parts a mesh tile holds, pickable (3D Tiles 1.1 conventions): EXT_mesh_features gives each
// vertex a feature ID, a row of the tile's EXT_structural_metadata property table, which names
// the part (class "part": id, name, path, material, source). Rows are the tile's own parts only, so
// a coarse tile that kept a few parts lists those few.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/tiling/chunk_input.h"

namespace lodforge {

// A tile's features: its distinct parts (global feature ids, ascending) and each vertex's row.
struct TileFeatures {
  std::vector<std::uint32_t> parts;
  std::vector<std::uint32_t> rows;  // one per vertex
};
// `features` is one global feature id per vertex (kNoFeature nowhere: the mesh is all parts).
TileFeatures tileFeatures(std::span<const std::uint32_t> features);

// The "_FEATURE_ID_0" attribute over `rows` (UNSIGNED_SHORT while the rows fit, else FLOAT,
// exact to 2^24; glTF has no 32-bit integer vertex attribute), backed by `storage`.
GlbVertexAttribute featureIdAttribute(std::span<const std::uint32_t> rows,
                                      std::vector<std::byte>& storage);

// The schema and the property table of `parts` (rows of `table`) into the writer; the table is
// property table 0.
Status addPartTable(GlbWriter& writer, const PartTable& table,
                    std::span<const std::uint32_t> parts);

// A group of triangles: their key and how many indices they take.
struct TriangleGroup {
  std::uint32_t key = 0;
  std::uint32_t indexCount = 0;
};
// Reorders the triangles (`indices`, in place) stably by `keyOf` (one per triangle, cache order
// kept within a key) and returns the groups in key order.
std::vector<TriangleGroup> groupTriangles(std::span<std::uint32_t> indices,
                                          std::span<const std::uint32_t> keyOf);

// The tile's triangles (`indices`, reordered in place) grouped by their part's material, stably
// (cache order is kept within a group), each group a primitive with its material added to the
// writer; parts without one share the writer's default. With `vertexColors` the base colour is
// already in the colours (readers bake it in): the material keeps only its alpha mode,
// metallic-roughness, double-sidedness and emission, over a white base.
std::vector<GlbPrimitive> groupByMaterial(GlbWriter& writer, const PartTable& table,
                                          std::span<const std::uint32_t> vertexFeatures,
                                          std::span<std::uint32_t> indices, bool vertexColors);

}  // namespace lodforge
