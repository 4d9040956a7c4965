// A textured tile's GLB parts: its atlas pages (tile_atlas.h) encoded (JPEG, PNG where the source
// has alpha, or WebP) as textures with their source materials, and its triangles grouped into a
// primitive per page (those of no texture last, untextured).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/tiles/tile_atlas.h"

namespace lodforge {

// How tiles of a textured input get their textures.
struct TileTexturing {
  const TextureTable* table = nullptr;
  const TexturePyramid* pyramid = nullptr;
  AtlasOptions atlas;
  ImageEncodeOptions encode;  // JPEG by default; a page whose source has alpha goes to PNG
};

// The encoding of one page: WebP as asked; otherwise JPEG, or PNG when the source has alpha.
ImageEncodeOptions pageEncoding(const TileTexturing& texturing, const AtlasPage& page);

// Bakes, encodes and writes the pages one at a time (one page's texels in memory) and their
// materials, reorders `indices` (a triangle's page is its first
// corner's, from `pageOfVertex`) stably by page, and returns one primitive per group.
Result<std::vector<GlbPrimitive>> addTilePages(GlbWriter& writer, TileAtlas& atlas,
                                               std::span<const std::uint32_t> pageOfVertex,
                                               std::span<std::uint32_t> indices,
                                               const TileTexturing& texturing, bool vertexColors);

}  // namespace lodforge
