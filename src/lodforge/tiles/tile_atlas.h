// A tile's own textures (re-baked at each level): its triangles grouped into charts (the
// pieces of surface whose texture coordinates run on without a seam; one larger than a page
// split into pieces of a page, its border vertices then doubled), each chart's texels
// copied from its source image's mip level for the tile's level — texel for texel, so a leaf
// keeps the source's full resolution and each level up half the texels per side — into pages
// of at most `maxSize` per side, packed with gutters, the empty space filled by pulling in the
// charts' own colours (so no mip level of a page samples black or a background), and new texture
// coordinates into the pages.
#pragma once

#include <cstdint>
#include <vector>

#include "lodforge/core/image.h"
#include "lodforge/core/status.h"
#include "lodforge/tiles/texture_pyramid.h"
#include "lodforge/tiling/chunk_input.h"
#include "lodforge/tiling/mesh_part.h"

namespace lodforge {

struct AtlasOptions {
  std::uint32_t maxSize = 4096;  // a page's side at most (texels): more texels make more pages
  std::uint32_t gutter = 2;      // texels of a chart's own border colour around it, at least
};

struct AtlasPage {
  std::uint32_t material = 0;  // the source material (into TextureTable::materials)
  std::uint32_t width = 0, height = 0;
  Image image;  // empty until baked (bakeAtlasPage)
};

// Where a chart's texels come from and go: its source image's level and the rectangle there
// (gutters included), and its place in its page.
struct AtlasChart {
  std::uint32_t material = 0, image = 0;
  float umin = 1e30f, vmin = 1e30f, umax = -1e30f, vmax = -1e30f;
  std::uint32_t level = 0;
  std::int64_t x0 = 0, y0 = 0;
  std::uint32_t w = 0, h = 0;
  std::uint32_t page = 0, ax = 0, ay = 0;
};

struct TileAtlas {
  // The tile's vertices: the mesh's, then copies of those on the borders of a chart the atlas
  // split (vertexSource: the mesh vertex each one is), and its triangles over them.
  std::vector<std::uint32_t> vertexSource;
  std::vector<std::uint32_t> indices;
  std::vector<AtlasPage> pages;
  std::vector<AtlasChart> layout;  // each chart: where its texels come from and go
  // Per vertex (of vertexSource): its texture coordinate in its page, and the page (~0u: a
  // vertex of no texture).
  std::vector<Vec2f> uvs;
  std::vector<std::uint32_t> pageOf;
  std::uint64_t charts = 0;
  std::uint64_t shrunkCharts = 0;  // charts a page cannot hold even split, from a coarser level
};

// The charts, their places and the new texture coordinates, pages not yet baked. `level` 0 is
// a leaf: the source's own texels.
TileAtlas layoutTileAtlas(const MeshPart& mesh, const TextureTable& table,
                          const TexturePyramid& pyramid, std::uint32_t level,
                          const AtlasOptions& options = {});
// Bakes page `page`'s texels (one page in memory at a time: the caller encodes it and clears
// its image before the next).
Status bakeAtlasPage(TileAtlas& atlas, std::size_t page, const TextureTable& table,
                     const TexturePyramid& pyramid);
// Both: every page baked.
Result<TileAtlas> bakeTileAtlas(const MeshPart& mesh, const TextureTable& table,
                                const TexturePyramid& pyramid, std::uint32_t level,
                                const AtlasOptions& options = {});
// Bytes baking a page of `side` x `side` texels takes at most: its texels (4), mask (1), a
// chart's texels read from the pyramid (up to a page, 4) and the fill's levels (4/3 at most).
inline std::uint64_t atlasPageBytes(std::uint32_t side) {
  return std::uint64_t{side} * side * 11;
}

// Fills the texels `mask` leaves out (0) from those it keeps, by pulling coarser averages of the
// kept ones down (push-pull): every texel ends up a colour of the nearby charts.
void fillEmptyTexels(Image& image, std::vector<std::uint8_t>& mask);

}  // namespace lodforge
