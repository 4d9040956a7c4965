#include "lodforge/tiles/tile_texture.h"

#include <algorithm>
#include <utility>

#include "lodforge/tiles/tile_features.h"

namespace lodforge {

ImageEncodeOptions pageEncoding(const TileTexturing& texturing, const AtlasPage& page) {
  ImageEncodeOptions encode = texturing.encode;
  const Material& material = texturing.table->materials[page.material];
  const bool alpha = texturing.table->images[material.baseColorImage].hasAlpha();
  if (encode.format == ImageFormat::kJpeg && alpha) encode.format = ImageFormat::kPng;
  return encode;
}

Result<std::vector<GlbPrimitive>> addTilePages(GlbWriter& writer, TileAtlas& atlas,
                                               std::span<const std::uint32_t> pageOfVertex,
                                               std::span<std::uint32_t> indices,
                                               const TileTexturing& texturing, bool vertexColors) {
  std::vector<std::optional<std::uint32_t>> materials(atlas.pages.size());
  for (std::size_t p = 0; p < atlas.pages.size(); ++p) {
    AtlasPage& page = atlas.pages[p];
    if (page.image.pixelCount() == 0)
      LODFORGE_TRY(bakeAtlasPage(atlas, p, *texturing.table, *texturing.pyramid));
    const ImageEncodeOptions encode = pageEncoding(texturing, page);
    Result<std::vector<std::byte>> bytes = encodeImage(page.image, encode);
    page.image = Image();  // the next page's texels take its place
    if (!bytes) return bytes.status();
    Material material = texturing.table->materials[page.material];
    // The page holds the chart texels only: what lies outside [0, 1] was baked in already.
    Result<std::uint32_t> texture =
        writer.addTexture(*bytes, encode.format, TextureWrap::kClamp, TextureWrap::kClamp);
    if (!texture) return texture.status();
    if (vertexColors) material.baseColor = {1, 1, 1, 1};
    materials[p] = writer.addMaterial(material, *texture);
  }
  std::vector<std::uint32_t> pageOf(indices.size() / 3);
  for (std::size_t t = 0; t < pageOf.size(); ++t) pageOf[t] = pageOfVertex[indices[3 * t]];
  std::vector<GlbPrimitive> primitives;
  for (const TriangleGroup& group : groupTriangles(indices, pageOf))
    primitives.push_back(
        {group.indexCount, group.key < materials.size() ? materials[group.key] : std::nullopt});
  return primitives;
}

}  // namespace lodforge
