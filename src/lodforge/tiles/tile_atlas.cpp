#include "lodforge/tiles/tile_atlas.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>

namespace lodforge {
namespace {

constexpr std::uint32_t kNone = ~0u;

struct Chart {
  std::uint32_t material = 0, image = 0;
  float umin = 1e30f, vmin = 1e30f, umax = -1e30f, vmax = -1e30f;
  std::uint32_t level = 0;
  std::int64_t x0 = 0, y0 = 0;  // the rectangle's corner in its level's texels (gutter included)
  std::uint32_t w = 0, h = 0;
  std::uint32_t page = 0, ax = 0, ay = 0;  // where it lies in its page
};

std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

// Per vertex, its chart (the textured triangles joined through shared vertices), numbered in
// order of first vertex; kNone for a vertex of no textured triangle.
std::vector<std::uint32_t> chartOfVertex(const MeshPart& mesh, const TextureTable& table,
                                         std::uint32_t& count) {
  std::vector<std::uint32_t> parent(mesh.vertexCount());
  std::iota(parent.begin(), parent.end(), 0u);
  std::vector<std::uint8_t> textured(mesh.vertexCount(), 0);
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    const std::uint32_t material = mesh.materials[a];
    if (material >= table.materials.size() || table.materials[material].baseColorImage == kNoImage)
      continue;  // (work files are checked: a material of no image draws untextured)
    textured[a] = textured[b] = textured[c] = 1;
    parent[findRoot(parent, b)] = findRoot(parent, a);
    parent[findRoot(parent, c)] = findRoot(parent, a);
  }
  std::vector<std::uint32_t> chart(mesh.vertexCount(), kNone), number(mesh.vertexCount(), kNone);
  count = 0;
  for (std::uint32_t v = 0; v < mesh.vertexCount(); ++v) {
    if (textured[v] == 0) continue;
    std::uint32_t& n = number[findRoot(parent, v)];
    if (n == kNone) n = count++;
    chart[v] = n;
  }
  return chart;
}

// Each chart's material, image and texture-coordinate bounds.
std::vector<Chart> describeCharts(const MeshPart& mesh, const TextureTable& table,
                                  std::span<const std::uint32_t> chartOf, std::uint32_t count) {
  std::vector<Chart> charts(count);
  for (std::uint32_t v = 0; v < mesh.vertexCount(); ++v) {
    if (chartOf[v] == kNone) continue;
    Chart& c = charts[chartOf[v]];
    const std::uint32_t material = mesh.materials[v];
    if (material < table.materials.size() && table.materials[material].baseColorImage != kNoImage) {
      c.material = material;
      c.image = table.materials[material].baseColorImage;
    }
    c.umin = std::min(c.umin, mesh.uvs[v].x), c.umax = std::max(c.umax, mesh.uvs[v].x);
    c.vmin = std::min(c.vmin, mesh.uvs[v].y), c.vmax = std::max(c.vmax, mesh.uvs[v].y);
  }
  return charts;
}

// The chart's rectangle at the tile's level, or the first coarser level whose rectangle fits a
// page (a chart wider than a page: a texture repeated many times over one surface).
bool placeInLevel(Chart& c, const TexturePyramid& pyramid, std::uint32_t level,
                  const AtlasOptions& options) {
  const std::uint32_t top = pyramid.levels(c.image) - 1;
  for (c.level = std::min(level, top);; ++c.level) {
    const double w = pyramid.width(c.image, c.level), h = pyramid.height(c.image, c.level);
    const double g = options.gutter;
    c.x0 = static_cast<std::int64_t>(std::floor(c.umin * w - g));
    c.y0 = static_cast<std::int64_t>(std::floor(c.vmin * h - g));
    const double x1 = std::ceil(c.umax * w + g), y1 = std::ceil(c.vmax * h + g);
    const double cw = std::max(x1 - static_cast<double>(c.x0), 1.0);
    const double ch = std::max(y1 - static_cast<double>(c.y0), 1.0);
    if ((cw <= options.maxSize && ch <= options.maxSize) || c.level == top) {
      c.w = static_cast<std::uint32_t>(std::min<double>(cw, options.maxSize));
      c.h = static_cast<std::uint32_t>(std::min<double>(ch, options.maxSize));
      return c.level == std::min(level, top);
    }
  }
}

std::uint32_t roundUp4(std::uint32_t x) {
  return (x + 3) / 4 * 4;
}

struct PageSize {
  std::uint32_t material = 0, width = 0, height = 0;
};

// Shelf packing, tallest first, of one material's charts into pages no wider or taller than
// maxSize (sized from the charts' total area, so small tiles get small pages).
void packCharts(std::vector<Chart>& charts, std::span<const std::uint32_t> members,
                std::uint32_t maxSize, std::vector<PageSize>& pages) {
  std::vector<std::uint32_t> order(members.begin(), members.end());
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return charts[a].h != charts[b].h ? charts[a].h > charts[b].h : charts[a].w > charts[b].w;
  });
  double area = 0;
  std::uint32_t widest = 1;
  for (std::uint32_t c : order) {
    area += static_cast<double>(charts[c].w) * charts[c].h;
    widest = std::max(widest, charts[c].w);
  }
  const std::uint32_t width = std::min(
      maxSize, std::max(widest, static_cast<std::uint32_t>(std::ceil(std::sqrt(area * 1.15)))));
  std::uint32_t x = 0, y = 0, shelf = 0;
  pages.push_back({charts[order.front()].material, 0, 0});
  for (std::uint32_t c : order) {
    Chart& chart = charts[c];
    if (x + chart.w > width) x = 0, y += shelf, shelf = 0;
    if (y + chart.h > maxSize) {
      pages.push_back({chart.material, 0, 0});
      x = y = shelf = 0;
    }
    chart.page = static_cast<std::uint32_t>(pages.size() - 1);
    chart.ax = x, chart.ay = y;
    x += chart.w;
    shelf = std::max(shelf, chart.h);
    PageSize& page = pages.back();
    page.width = std::max(page.width, roundUp4(x));
    page.height = std::max(page.height, roundUp4(y + chart.h));
  }
}

// Copies each chart's texels from the pyramid into its page.
Status bakeCharts(const std::vector<Chart>& charts, const TextureTable& table,
                  const TexturePyramid& pyramid, TileAtlas& atlas,
                  std::vector<std::vector<std::uint8_t>>& masks) {
  std::vector<std::uint8_t> texels;
  for (const Chart& c : charts) {
    const Material& material = table.materials[c.material];
    texels.resize(std::size_t{c.w} * c.h * 4);
    LODFORGE_TRY(pyramid.read(c.image, c.level, c.x0, c.y0, c.w, c.h, material.wrapS,
                              material.wrapT, texels.data()));
    Image& page = atlas.pages[c.page].image;
    for (std::uint32_t row = 0; row < c.h; ++row) {
      const std::size_t at = std::size_t{c.ay + row} * page.width + c.ax;
      std::copy_n(texels.data() + 4 * std::size_t{row} * c.w, 4 * std::size_t{c.w},
                  page.rgba.data() + 4 * at);
      std::fill_n(masks[c.page].data() + at, c.w, std::uint8_t{1});
    }
  }
  return {};
}

}  // namespace

Result<TileAtlas> bakeTileAtlas(const MeshPart& mesh, const TextureTable& table,
                                const TexturePyramid& pyramid, std::uint32_t level,
                                const AtlasOptions& options) {
  assert(mesh.uvs.size() == mesh.vertexCount() && mesh.materials.size() == mesh.vertexCount());
  assert(options.maxSize >= 4 + 2 * options.gutter);
  TileAtlas atlas;
  std::uint32_t count = 0;
  const std::vector<std::uint32_t> chartOf = chartOfVertex(mesh, table, count);
  std::vector<Chart> charts = describeCharts(mesh, table, chartOf, count);
  atlas.charts = count;
  std::vector<std::vector<std::uint32_t>> byMaterial(table.materials.size());
  for (std::uint32_t c = 0; c < count; ++c) {
    if (!placeInLevel(charts[c], pyramid, level, options)) ++atlas.shrunkCharts;
    byMaterial[charts[c].material].push_back(c);
  }
  std::vector<PageSize> sizes;
  for (const std::vector<std::uint32_t>& members : byMaterial) {
    if (!members.empty()) packCharts(charts, members, options.maxSize, sizes);
  }
  std::vector<std::vector<std::uint8_t>> masks;
  for (const PageSize& size : sizes) {
    atlas.pages.push_back({size.material, Image(size.width, size.height)});
    masks.emplace_back(std::size_t{size.width} * size.height, 0);
  }
  LODFORGE_TRY(bakeCharts(charts, table, pyramid, atlas, masks));
  for (std::size_t p = 0; p < atlas.pages.size(); ++p)
    fillEmptyTexels(atlas.pages[p].image, masks[p]);
  // Texture coordinates into the pages: texel for texel of the chart's level.
  atlas.uvs.assign(mesh.vertexCount(), Vec2f{});
  atlas.pageOf.assign(mesh.vertexCount(), kNone);
  for (std::uint32_t v = 0; v < mesh.vertexCount(); ++v) {
    if (chartOf[v] == kNone) continue;
    const Chart& c = charts[chartOf[v]];
    const Image& page = atlas.pages[c.page].image;
    const double w = pyramid.width(c.image, c.level), h = pyramid.height(c.image, c.level);
    atlas.uvs[v] = {
        static_cast<float>((mesh.uvs[v].x * w - static_cast<double>(c.x0) + c.ax) / page.width),
        static_cast<float>((mesh.uvs[v].y * h - static_cast<double>(c.y0) + c.ay) / page.height)};
    atlas.pageOf[v] = c.page;
  }
  return atlas;
}

void fillEmptyTexels(Image& image, std::vector<std::uint8_t>& mask) {
  assert(mask.size() == image.pixelCount());
  // Pull: averages of the kept texels, level by level, down to 1 x 1.
  struct Level {
    std::uint32_t w, h;
    std::vector<float> rgba;  // premultiplied by the weight in [3]
  };
  std::vector<Level> levels;
  Level base{image.width, image.height, std::vector<float>(image.pixelCount() * 4, 0.0f)};
  for (std::size_t i = 0; i < image.pixelCount(); ++i) {
    if (mask[i] == 0) continue;
    for (std::size_t c = 0; c < 3; ++c) base.rgba[4 * i + c] = image.rgba[4 * i + c];
    base.rgba[4 * i + 3] = 1;
  }
  levels.push_back(std::move(base));
  while (levels.back().w > 1 || levels.back().h > 1) {
    const Level& fine = levels.back();
    Level coarse{(fine.w + 1) / 2, (fine.h + 1) / 2, {}};
    coarse.rgba.assign(std::size_t{coarse.w} * coarse.h * 4, 0.0f);
    for (std::uint32_t y = 0; y < fine.h; ++y)
      for (std::uint32_t x = 0; x < fine.w; ++x)
        for (std::size_t c = 0; c < 4; ++c)
          coarse.rgba[4 * (std::size_t{y / 2} * coarse.w + x / 2) + c] +=
              fine.rgba[4 * (std::size_t{y} * fine.w + x) + c];
    levels.push_back(std::move(coarse));
  }
  // Push: an empty texel takes its coarser level's (filled) average.
  float* top = levels.back().rgba.data();
  if (top[3] > 0)
    for (int c = 0; c < 3; ++c) top[c] /= top[3];
  for (std::size_t l = levels.size() - 1; l-- > 0;) {
    Level& fine = levels[l];
    const Level& coarse = levels[l + 1];
    for (std::uint32_t y = 0; y < fine.h; ++y) {
      for (std::uint32_t x = 0; x < fine.w; ++x) {
        float* f = &fine.rgba[4 * (std::size_t{y} * fine.w + x)];
        if (f[3] > 0) {
          for (int c = 0; c < 3; ++c) f[c] /= f[3];
        } else {
          const float* g = &coarse.rgba[4 * (std::size_t{y / 2} * coarse.w + x / 2)];
          for (int c = 0; c < 3; ++c) f[c] = g[c];
        }
        f[3] = 1;
      }
    }
  }
  const Level& filled = levels.front();
  for (std::size_t i = 0; i < image.pixelCount(); ++i) {
    if (mask[i] != 0) continue;
    for (std::size_t c = 0; c < 3; ++c)
      image.rgba[4 * i + c] =
          static_cast<std::uint8_t>(std::lround(std::clamp(filled.rgba[4 * i + c], 0.0f, 255.0f)));
    image.rgba[4 * i + 3] = 255;
    mask[i] = 1;
  }
}

}  // namespace lodforge
