#include "lodforge/tiles/tile_content.h"

#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <meshoptimizer.h>

#include "lodforge/core/mesh.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/tiles/tile_features.h"
#include "lodforge/tiles/tile_texture.h"

namespace lodforge {

namespace {

// The tile's mesh as its atlas has it: a vertex the atlas doubled (on a split chart's border)
// copied, the triangles over the copies.
MeshPart expandedFor(const MeshPart& mesh, const TileAtlas& atlas) {
  MeshPart out;
  const auto copy = [&](const auto& from, auto& to) {
    if (from.empty()) return;
    to.reserve(atlas.vertexSource.size());
    for (std::uint32_t v : atlas.vertexSource) to.push_back(from[v]);
  };
  copy(mesh.positions, out.positions);
  copy(mesh.colors, out.colors);
  copy(mesh.normals, out.normals);
  copy(mesh.features, out.features);
  out.indices = atlas.indices;
  return out;
}

// A tile's vertex arrays as its GLB holds them: relative to its centre, y-up, in fetch order.
struct TileArrays {
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<std::uint32_t> features, indices;
  std::vector<Vec2f> uvs;
  std::vector<std::uint32_t> pageOf;  // textured: each vertex's atlas page
};

// Triangles in vertex-cache order, then vertices in first-use order (faster to draw, and what
// the meshopt codec compresses best). The FIFO variant (Tipsify) is 2-3x faster than
// meshopt_optimizeVertexCache, as good on scan tiles (ACMR 0.60 vs 0.63 for a 16-entry FIFO),
// and tile writing was ~10 % of a build. Returns each vertex's new place (~0u: unused).
std::vector<std::uint32_t> fetchOrder(const MeshPart& mesh, TileArrays& out, std::size_t& used) {
  constexpr std::size_t kCacheSize = 16;
  out.indices.resize(mesh.indices.size());
  meshopt_optimizeVertexCacheFifo(out.indices.data(), mesh.indices.data(), mesh.indices.size(),
                                  mesh.positions.size(), kCacheSize);
  std::vector<std::uint32_t> remap(mesh.positions.size());
  used = meshopt_optimizeVertexFetchRemap(remap.data(), out.indices.data(), out.indices.size(),
                                          mesh.positions.size());
  meshopt_remapIndexBuffer(out.indices.data(), out.indices.data(), out.indices.size(),
                           remap.data());
  return remap;
}

TileArrays tileArrays(const MeshPart& mesh, Vec3d center, bool colors, bool features,
                      const TileAtlas* atlas) {
  TileArrays out;
  std::size_t used = 0;
  const std::vector<std::uint32_t> remap = fetchOrder(mesh, out, used);
  out.positions.resize(used);
  out.normals.resize(used);
  out.colors.resize(colors && !mesh.colors.empty() ? used : 0);
  out.features.resize(features ? used : 0);
  out.uvs.resize(atlas ? used : 0);
  out.pageOf.resize(atlas ? used : 0);
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const std::uint32_t to = remap[v];
    if (to == ~0u) continue;
    out.positions[to] = toFloat(mesh.positions[v] - center);
    if (atlas) out.uvs[to] = atlas->uvs[v], out.pageOf[to] = atlas->pageOf[v];
    if (features) out.features[to] = mesh.features[v];
    if (!out.colors.empty()) out.colors[to] = mesh.colors[v];
    if (!mesh.normals.empty()) out.normals[to] = mesh.normals[v];
  }
  // The input's normals, the same in every tile that holds a vertex; from this mesh alone only
  // when there are none (which leaves shading seams along tile borders).
  if (mesh.normals.empty()) computeVertexNormals(out.positions, out.indices, out.normals);
  for (Vec3f& p : out.positions) p = toYUp(p);
  for (Vec3f& n : out.normals) n = toYUp(n);
  return out;
}

}  // namespace

Status writeTileContent(const MeshPart& input, const Aabbd& bounds, const std::string& path,
                        const TileContentOptions& options) {
  const Vec3d center = bounds.center();
  const bool textured = options.texturing != nullptr && !input.uvs.empty();
  // Laid out now; each page is baked as it is written (addTilePages).
  TileAtlas atlas;
  MeshPart expanded;
  if (textured) {
    atlas = layoutTileAtlas(input, *options.texturing->table, *options.texturing->pyramid,
                            options.level, options.texturing->atlas);
    expanded = expandedFor(input, atlas);
  }
  const MeshPart& mesh = textured ? expanded : input;
  const bool features =
      options.parts != nullptr && !options.parts->empty() && !mesh.features.empty();
  // Features come from work files: one that names no part is damage, not a row to read past.
  if (features)
    for (std::uint32_t f : mesh.features)
      if (f >= options.parts->size())
        return badInput(path, fmt::format("tile mesh names part {} of {} (damaged work file?)", f,
                                          options.parts->size()));
  TileArrays arrays =
      tileArrays(mesh, center, options.colors, features, textured ? &atlas : nullptr);
  // A tile of parts has its one node straight in the scene: 3d-tiles-renderer 0.4's
  // EXT_mesh_features loader fails on a node without a mesh (the root that holds the centre).
  Result<GlbWriter> writer =
      GlbWriter::create(path, {.doubleSided = false,
                               .meshoptCompression = options.meshoptCompression,
                               .flatScene = features});
  if (!writer) return writer.status();
  GlbMeshData data{arrays.positions, arrays.normals, arrays.colors, arrays.indices,
                   options.quantize};
  data.uvs = arrays.uvs;
  std::vector<std::byte> featureStorage;
  std::vector<GlbVertexAttribute> extra;
  std::vector<GlbPrimitive> primitives;
  if (features) {
    const TileFeatures tile = tileFeatures(arrays.features);
    extra.push_back(featureIdAttribute(tile.rows, featureStorage));
    LODFORGE_TRY(addPartTable(*writer, *options.parts, tile.parts));
    data.extraAttributes = extra;
    data.featureIds = GlbFeatureIds{static_cast<std::uint32_t>(tile.parts.size()), 0};
    if (!textured)
      primitives = groupByMaterial(*writer, *options.parts, arrays.features, arrays.indices,
                                   !arrays.colors.empty());
  }
  if (textured) {
    Result<std::vector<GlbPrimitive>> pages = addTilePages(
        *writer, atlas, arrays.pageOf, arrays.indices, *options.texturing, !arrays.colors.empty());
    if (!pages) return pages.status();
    primitives = std::move(*pages);
  }
  data.primitives = primitives;
  Result<std::uint32_t> glbMesh = writer->addMesh(data, "tile");
  if (!glbMesh) return glbMesh.status();
  if (features) {
    const Mat4d translation = Mat4d::translation(toYUp(center));
    writer->addNode("tile", *glbMesh, &translation);
  } else {
    writer->addNode("tile", *glbMesh);
    writer->setRootTranslation(toYUp(center));
  }
  return writer->finish();
}

bool tileQuantized(const OctreeNode& node) {
  return node.level == 0 || tileQuantizationError(node, true) <= node.geometricError / 32;
}

double tileQuantizationError(const OctreeNode& node, bool quantize) {
  if (!quantize || node.triangles == 0) return 0;
  return glbQuantizationError(node.bounds);
}

}  // namespace lodforge
