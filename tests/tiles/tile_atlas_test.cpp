#include "lodforge/tiles/tile_atlas.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "lodforge/io/image/image_codec.h"
#include "test_support.h"

namespace lodforge {
namespace {

constexpr std::uint32_t kSize = 64;

// A checker of 8-texel squares in colours none of which is black, with a gradient inside each.
Image checker() {
  Image image(kSize, kSize);
  for (std::uint32_t y = 0; y < kSize; ++y)
    for (std::uint32_t x = 0; x < kSize; ++x) {
      std::uint8_t* p = &image.rgba[4 * (std::size_t{y} * kSize + x)];
      const bool odd = (x / 8 + y / 8) % 2 == 1;
      p[0] = static_cast<std::uint8_t>(odd ? 220 : 40 + x);
      p[1] = static_cast<std::uint8_t>(odd ? 60 + y : 180);
      p[2] = static_cast<std::uint8_t>(30 + (x + y) % 64);
      p[3] = 255;
    }
  return image;
}

struct Scene {
  test::TempDir dir;
  Image source = checker();
  TextureTable table;
  std::optional<TexturePyramid> pyramid;

  explicit Scene(TextureWrap wrap = TextureWrap::kRepeat) {
    Result<std::vector<std::byte>> png = encodeImage(source, {.format = ImageFormat::kPng});
    EXPECT_TRUE(png.ok());
    ImageSource image{.name = "checker", .bytes = *png};
    EXPECT_TRUE(probeImage(image).ok());
    table.images.push_back(image);
    Material material;
    material.baseColorImage = 0;
    material.wrapS = material.wrapT = wrap;
    table.materials.push_back(material);
    Result<TexturePyramid> built =
        TexturePyramid::build(table.images, dir.path().string(), 1 << 20);
    EXPECT_TRUE(built.ok());
    pyramid.emplace(std::move(*built));
  }
};

// A grid of n x n quads over [x0, x0 + 1] x [0, 1] whose texture coordinates run over
// [u0, u1] x [v0, v1] (one chart), appended to `mesh`.
void addChart(MeshPart& mesh, double x0, float u0, float v0, float u1, float v1, int n = 4) {
  const auto first = mesh.vertexCount();
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      mesh.positions.push_back({x0 + double(i) / n, double(j) / n, 0});
      mesh.uvs.push_back(
          {u0 + (u1 - u0) * float(i) / float(n), v0 + (v1 - v0) * float(j) / float(n)});
      mesh.materials.push_back(0);
    }
  const auto at = [&](int i, int j) { return first + static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
}

const std::uint8_t* texel(const Image& image, std::int64_t x, std::int64_t y) {
  return &image.rgba[4 * (static_cast<std::size_t>(y) * image.width + static_cast<std::size_t>(x))];
}

// Every source texel whose centre lies in the chart's UV range is the page texel the chart's
// (integer) offset puts it at: texel for texel of `level` of the source.
void expectTexelExact(const MeshPart& mesh, const TileAtlas& atlas, const Image& level,
                      std::uint32_t firstVertex, std::uint32_t lastVertex, TextureWrap wrap) {
  const Image& page = atlas.pages[atlas.pageOf[firstVertex]].image;
  const double dx = atlas.uvs[firstVertex].x * page.width - mesh.uvs[firstVertex].x * level.width;
  const double dy = atlas.uvs[firstVertex].y * page.height - mesh.uvs[firstVertex].y * level.height;
  ASSERT_NEAR(dx, std::round(dx), 1e-3);
  ASSERT_NEAR(dy, std::round(dy), 1e-3);
  float umin = 1e9f, umax = -1e9f, vmin = 1e9f, vmax = -1e9f;
  for (std::uint32_t v = firstVertex; v < lastVertex; ++v) {
    const double ox = atlas.uvs[v].x * page.width - mesh.uvs[v].x * level.width;
    EXPECT_NEAR(ox, dx, 1e-3);  // one translation for the whole chart
    umin = std::min(umin, mesh.uvs[v].x), umax = std::max(umax, mesh.uvs[v].x);
    vmin = std::min(vmin, mesh.uvs[v].y), vmax = std::max(vmax, mesh.uvs[v].y);
  }
  int compared = 0;
  for (auto y = static_cast<std::int64_t>(std::floor(vmin * level.height));
       y < std::ceil(vmax * level.height); ++y)
    for (auto x = static_cast<std::int64_t>(std::floor(umin * level.width));
         x < std::ceil(umax * level.width); ++x) {
      const auto px = x + static_cast<std::int64_t>(std::round(dx));
      const auto py = y + static_cast<std::int64_t>(std::round(dy));
      ASSERT_GE(px, 0);
      ASSERT_LT(px, page.width);
      const std::int64_t sx = wrapTexel(x, level.width, wrap),
                         sy = wrapTexel(y, level.height, wrap);
      ASSERT_EQ(0, std::memcmp(texel(page, px, py), texel(level, sx, sy), 4)) << x << "," << y;
      ++compared;
    }
  EXPECT_GT(compared, 0);
}

TEST(TileAtlas, ALeafCopiesItsChartsTexelForTexel) {
  Scene scene;
  MeshPart mesh;
  addChart(mesh, 0, 0.25f, 0.25f, 0.75f, 0.6f);
  addChart(mesh, 2, 0.0f, 0.7f, 0.3f, 1.0f);  // a second chart, elsewhere in the texture
  Result<TileAtlas> atlas = bakeTileAtlas(mesh, scene.table, *scene.pyramid, 0);
  ASSERT_TRUE(atlas.ok()) << atlas.error().message;
  EXPECT_EQ(atlas->charts, 2u);
  EXPECT_EQ(atlas->shrunkCharts, 0u);
  ASSERT_EQ(atlas->pages.size(), 1u);
  expectTexelExact(mesh, *atlas, scene.source, 0, 25, TextureWrap::kRepeat);
  expectTexelExact(mesh, *atlas, scene.source, 25, 50, TextureWrap::kRepeat);
  // The page holds the charts and their gutters, not the whole texture.
  const Image& page = atlas->pages[0].image;
  EXPECT_LT(std::size_t{page.width} * page.height, std::size_t{kSize} * kSize);
}

TEST(TileAtlas, EachLevelUpHasHalfTheTexelsPerSide) {
  Scene scene;
  MeshPart mesh;
  addChart(mesh, 0, 0.0f, 0.0f, 1.0f, 1.0f);
  Image level = scene.source;
  std::uint64_t previous = 0;
  for (std::uint32_t l = 0; l < 3; ++l) {
    Result<TileAtlas> atlas = bakeTileAtlas(mesh, scene.table, *scene.pyramid, l);
    ASSERT_TRUE(atlas.ok());
    expectTexelExact(mesh, *atlas, level, 0, mesh.vertexCount(), TextureWrap::kRepeat);
    const Image& page = atlas->pages[0].image;
    const std::uint64_t texels = std::uint64_t{page.width} * page.height;
    if (l > 0) {
      EXPECT_LT(texels, previous / 2);  // a quarter, plus the gutters
    }
    previous = texels;
    level = halveImage(level);
  }
}

TEST(TileAtlas, ChartsAcrossTheWrapReadTheRepeatedOrMirroredTexture) {
  for (TextureWrap wrap : {TextureWrap::kRepeat, TextureWrap::kMirror}) {
    Scene scene(wrap);
    MeshPart mesh;
    addChart(mesh, 0, 0.8f, -0.3f, 1.4f, 0.2f);  // over u = 1 and v = 0
    Result<TileAtlas> atlas = bakeTileAtlas(mesh, scene.table, *scene.pyramid, 0);
    ASSERT_TRUE(atlas.ok());
    expectTexelExact(mesh, *atlas, scene.source, 0, mesh.vertexCount(), wrap);
    for (const Vec2f& uv : atlas->uvs) {
      EXPECT_GE(uv.x, 0.0f);
      EXPECT_LE(uv.x, 1.0f);  // into the page, which is clamped
    }
  }
}

TEST(TileAtlas, NoMipLevelOfAPageHasAnEmptyTexel) {
  Scene scene;
  MeshPart mesh;
  for (int c = 0; c < 6; ++c)
    addChart(mesh, 2 * c, 0.1f * float(c), 0.05f * float(c), 0.1f * float(c) + 0.12f,
             0.05f * float(c) + 0.3f, 2);
  Result<TileAtlas> atlas =
      bakeTileAtlas(mesh, scene.table, *scene.pyramid, 0, {.maxSize = 4096, .gutter = 2});
  ASSERT_TRUE(atlas.ok());
  Image level = atlas->pages[0].image;
  // Black is no colour of the checker: any black texel, at any level, is an unfilled one.
  while (true) {
    for (std::size_t i = 0; i < level.pixelCount(); ++i) {
      const std::uint8_t* p = &level.rgba[4 * i];
      ASSERT_FALSE(p[0] < 20 && p[1] < 20 && p[2] < 20) << "texel " << i << " of " << level.width;
      ASSERT_EQ(p[3], 255);
    }
    if (level.width == 1 && level.height == 1) break;
    level = halveImage(level);
  }
}

TEST(TileAtlas, MoreTexelsThanAPageMakeMorePagesAndALargerChartIsSplit) {
  Scene scene;
  MeshPart mesh;
  addChart(mesh, 0, 0.0f, 0.0f, 0.6f, 0.6f);  // 39 x 39 texels with gutters each
  addChart(mesh, 2, 0.2f, 0.2f, 0.8f, 0.8f);
  Result<TileAtlas> atlas =
      bakeTileAtlas(mesh, scene.table, *scene.pyramid, 0, {.maxSize = 48, .gutter = 2});
  ASSERT_TRUE(atlas.ok());
  EXPECT_EQ(atlas->pages.size(), 2u);
  for (const AtlasPage& page : atlas->pages) {
    EXPECT_LE(page.image.width, 48u);
    EXPECT_LE(page.image.height, 48u);
  }
  EXPECT_EQ(atlas->shrunkCharts, 0u);
  expectTexelExact(mesh, *atlas, scene.source, 0, 25, TextureWrap::kRepeat);
  expectTexelExact(mesh, *atlas, scene.source, 25, 50, TextureWrap::kRepeat);

  // A chart wider than a page is split into pieces of a page, at full resolution, its border
  // vertices doubled; each triangle's texels still those of the source, one for one.
  MeshPart wide;
  addChart(wide, 0, 0.0f, 0.0f, 3.0f, 0.5f, 12);  // 192 texels wide: over any 64-texel page
  atlas = bakeTileAtlas(wide, scene.table, *scene.pyramid, 0, {.maxSize = 64, .gutter = 2});
  ASSERT_TRUE(atlas.ok());
  EXPECT_EQ(atlas->shrunkCharts, 0u);
  EXPECT_GT(atlas->charts, 3u);
  EXPECT_GT(atlas->vertexSource.size(), wide.vertexCount());
  for (const AtlasPage& page : atlas->pages) EXPECT_LE(page.image.width, 64u);
  for (std::size_t t = 0; t < atlas->indices.size(); t += 3) {
    const Image& page = atlas->pages[atlas->pageOf[atlas->indices[t]]].image;
    double offset[3][2];
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = atlas->indices[t + k];
      ASSERT_EQ(atlas->pageOf[v], atlas->pageOf[atlas->indices[t]]);
      const Vec2f uv = wide.uvs[atlas->vertexSource[v]];
      offset[k][0] = atlas->uvs[v].x * page.width - uv.x * kSize;
      offset[k][1] = atlas->uvs[v].y * page.height - uv.y * kSize;
      ASSERT_NEAR(offset[k][0], std::round(offset[k][0]), 1e-3);
      ASSERT_NEAR(offset[k][0], offset[0][0], 1e-3);
      ASSERT_NEAR(offset[k][1], offset[0][1], 1e-3);
    }
    // The texel under the triangle's centre, in the page and in the (repeated) source.
    double u = 0, v = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      u += wide.uvs[atlas->vertexSource[atlas->indices[t + k]]].x / 3.0;
      v += wide.uvs[atlas->vertexSource[atlas->indices[t + k]]].y / 3.0;
    }
    const auto sx = static_cast<std::int64_t>(std::floor(u * kSize));
    const auto sy = static_cast<std::int64_t>(std::floor(v * kSize));
    const auto px = sx + static_cast<std::int64_t>(std::round(offset[0][0]));
    const auto py = sy + static_cast<std::int64_t>(std::round(offset[0][1]));
    ASSERT_EQ(0, std::memcmp(texel(page, px, py),
                             texel(scene.source, wrapTexel(sx, kSize, TextureWrap::kRepeat),
                                   wrapTexel(sy, kSize, TextureWrap::kRepeat)),
                             4));
  }
  // A texture repeated too often to split finer is taken from a coarser level instead.
  MeshPart huge;
  addChart(huge, 0, 0.0f, 0.0f, 300.0f, 0.5f, 2);
  atlas = bakeTileAtlas(huge, scene.table, *scene.pyramid, 0, {.maxSize = 64, .gutter = 2});
  ASSERT_TRUE(atlas.ok());
  EXPECT_GT(atlas->shrunkCharts, 0u);
}

TEST(TileAtlas, UntexturedTrianglesHaveNoPage) {
  Scene scene;
  MeshPart mesh;
  addChart(mesh, 0, 0.1f, 0.1f, 0.4f, 0.4f, 1);
  addChart(mesh, 2, 0.1f, 0.1f, 0.4f, 0.4f, 1);
  for (std::size_t v = 4; v < 8; ++v) mesh.materials[v] = ~0u;
  Result<TileAtlas> atlas = bakeTileAtlas(mesh, scene.table, *scene.pyramid, 0);
  ASSERT_TRUE(atlas.ok());
  EXPECT_EQ(atlas->charts, 1u);
  for (std::size_t v = 0; v < 4; ++v) EXPECT_EQ(atlas->pageOf[v], 0u);
  for (std::size_t v = 4; v < 8; ++v) EXPECT_EQ(atlas->pageOf[v], ~0u);
}

}  // namespace
}  // namespace lodforge
