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
  // Triangles in vertex-cache order, then vertices in first-use order (faster to draw, and what
  // the meshopt codec compresses best). The FIFO variant (Tipsify) is 2-3x faster than
  // meshopt_optimizeVertexCache, as good on scan tiles (ACMR 0.60 vs 0.63 for a 16-entry FIFO),
  // and tile writing was ~10 % of a build.
  constexpr std::size_t kCacheSize = 16;
  std::vector<std::uint32_t> indices(mesh.indices.size());
  meshopt_optimizeVertexCacheFifo(indices.data(), mesh.indices.data(), mesh.indices.size(),
                                  mesh.positions.size(), kCacheSize);
  std::vector<std::uint32_t> remap(mesh.positions.size());
  const std::size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), indices.data(),
                                                            indices.size(), mesh.positions.size());
  meshopt_remapIndexBuffer(indices.data(), indices.data(), indices.size(), remap.data());
  std::vector<Vec3f> positions(used);
  std::vector<Rgba8> colors(options.colors && !mesh.colors.empty() ? used : 0);
  std::vector<Vec3f> normals(used);
  const bool features =
      options.parts != nullptr && !options.parts->empty() && !mesh.features.empty();
  // Features come from work files: one that names no part is damage, not a row to read past.
  if (features)
    for (std::uint32_t f : mesh.features)
      if (f >= options.parts->size())
        return badInput(path, fmt::format("tile mesh names part {} of {} (damaged work file?)", f,
                                          options.parts->size()));
  std::vector<std::uint32_t> vertexFeatures(features ? used : 0);
  std::vector<Vec2f> uvs(textured ? used : 0);
  std::vector<std::uint32_t> pageOf(textured ? used : 0);
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    if (remap[v] == ~0u) continue;
    positions[remap[v]] = toFloat(mesh.positions[v] - center);
    if (textured) {
      uvs[remap[v]] = atlas.uvs[v];
      pageOf[remap[v]] = atlas.pageOf[v];
    }
    if (features) vertexFeatures[remap[v]] = mesh.features[v];
    if (!colors.empty()) colors[remap[v]] = mesh.colors[v];
    if (!mesh.normals.empty()) normals[remap[v]] = mesh.normals[v];
  }
  // The input's normals, the same in every tile that holds a vertex; from this mesh alone only
  // when there are none (which leaves shading seams along tile borders).
  if (mesh.normals.empty()) computeVertexNormals(positions, indices, normals);
  for (Vec3f& p : positions) p = toYUp(p);
  for (Vec3f& n : normals) n = toYUp(n);
  // A tile of parts has its one node straight in the scene: 3d-tiles-renderer 0.4's
  // EXT_mesh_features loader fails on a node without a mesh (the root that holds the centre).
  Result<GlbWriter> writer =
      GlbWriter::create(path, {.doubleSided = false,
                               .meshoptCompression = options.meshoptCompression,
                               .flatScene = features});
  if (!writer) return writer.status();
  GlbMeshData data{positions, normals, colors, indices, options.quantize};
  data.uvs = uvs;
  std::vector<std::byte> featureStorage;
  std::vector<GlbVertexAttribute> extra;
  std::vector<GlbPrimitive> primitives;
  if (features) {
    const TileFeatures tile = tileFeatures(vertexFeatures);
    extra.push_back(featureIdAttribute(tile.rows, featureStorage));
    LODFORGE_TRY(addPartTable(*writer, *options.parts, tile.parts));
    data.extraAttributes = extra;
    data.featureIds = GlbFeatureIds{static_cast<std::uint32_t>(tile.parts.size()), 0};
    if (!textured) {
      primitives =
          groupByMaterial(*writer, *options.parts, vertexFeatures, indices, !colors.empty());
      data.primitives = primitives;
    }
  }
  if (textured) {
    Result<std::vector<GlbPrimitive>> pages =
        addTilePages(*writer, atlas, pageOf, indices, *options.texturing, !colors.empty());
    if (!pages) return pages.status();
    primitives = std::move(*pages);
    data.primitives = primitives;
  }
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
  return 0.5 * std::sqrt(3.0) * glbQuantizationStep(node.bounds);
}

}  // namespace lodforge
