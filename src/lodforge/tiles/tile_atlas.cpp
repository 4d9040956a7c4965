#include "lodforge/tiles/tile_atlas.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <unordered_map>

namespace lodforge {
namespace {

constexpr std::uint32_t kNone = ~0u;

using Chart = AtlasChart;

std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

bool texturedTriangle(const MeshPart& mesh, const TextureTable& table, std::size_t t) {
  const std::uint32_t material = mesh.materials[mesh.indices[t]];
  // (Work files are checked: a material of no image draws untextured.)
  return material < table.materials.size() && table.materials[material].baseColorImage != kNoImage;
}

// Per triangle, its chart (the textured triangles joined through shared vertices), numbered
// in order of first triangle; kNone for a triangle of no texture.
std::vector<std::uint32_t> chartOfTriangle(const MeshPart& mesh, const TextureTable& table,
                                           std::uint32_t& count) {
  std::vector<std::uint32_t> parent(mesh.vertexCount());
  std::iota(parent.begin(), parent.end(), 0u);
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    if (!texturedTriangle(mesh, table, t)) continue;
    const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    parent[findRoot(parent, b)] = findRoot(parent, a);
    parent[findRoot(parent, c)] = findRoot(parent, a);
  }
  std::vector<std::uint32_t> chart(mesh.indices.size() / 3, kNone),
      number(mesh.vertexCount(), kNone);
  count = 0;
  for (std::size_t t = 0; t < chart.size(); ++t) {
    if (!texturedTriangle(mesh, table, 3 * t)) continue;
    std::uint32_t& n = number[findRoot(parent, mesh.indices[3 * t])];
    if (n == kNone) n = count++;
    chart[t] = n;
  }
  return chart;
}

// Each chart's material, image and texture-coordinate bounds, from its triangles' corners.
std::vector<Chart> describeCharts(const MeshPart& mesh, const TextureTable& table,
                                  std::span<const std::uint32_t> chartOf, std::uint32_t count) {
  std::vector<Chart> charts(count);
  for (std::size_t t = 0; t < chartOf.size(); ++t) {
    if (chartOf[t] == kNone) continue;
    Chart& c = charts[chartOf[t]];
    c.material = mesh.materials[mesh.indices[3 * t]];
    c.image = table.materials[c.material].baseColorImage;
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec2f uv = mesh.uvs[mesh.indices[3 * t + k]];
      c.umin = std::min(c.umin, uv.x), c.umax = std::max(c.umax, uv.x);
      c.vmin = std::min(c.vmin, uv.y), c.vmax = std::max(c.vmax, uv.y);
    }
  }
  return charts;
}

// A chart whose texels at `level` are more than a page splits into pieces of a page each, by
// where its triangles' centres fall in a grid over its texture coordinates: the finest level
// keeps every texel (more pages) instead of a coarser level's (a blur). Renumbers `chartOf`.
std::uint32_t splitLargeCharts(const MeshPart& mesh, const TextureTable& table,
                               const TexturePyramid& pyramid, std::uint32_t level,
                               const AtlasOptions& options, std::vector<Chart>& charts,
                               std::vector<std::uint32_t>& chartOf) {
  // A cell's side in texels: a page less the gutters and a texel of rounding on each side.
  const double cell = std::max(1.0, double(options.maxSize) - 2.0 * options.gutter - 4.0);
  std::vector<std::uint64_t> first(charts.size() + 1, 0);  // first new chart of each
  std::vector<std::array<std::uint32_t, 2>> grid(charts.size(), {1, 1});
  for (std::size_t c = 0; c < charts.size(); ++c) {
    const Chart& chart = charts[c];
    const std::uint32_t l = std::min(level, pyramid.levels(chart.image) - 1);
    const double w = double(chart.umax - chart.umin) * pyramid.width(chart.image, l);
    const double h = double(chart.vmax - chart.vmin) * pyramid.height(chart.image, l);
    // (A chart of a texture repeated thousands of times is not cut finer than 64 x 64 pieces.)
    grid[c] = {static_cast<std::uint32_t>(std::clamp(std::ceil(w / cell), 1.0, 64.0)),
               static_cast<std::uint32_t>(std::clamp(std::ceil(h / cell), 1.0, 64.0))};
    first[c + 1] = first[c] + std::uint64_t{grid[c][0]} * grid[c][1];
  }
  // (More pieces than a tile has triangles cannot be: each holds one. Past that, nothing splits.)
  if (first.back() == charts.size() || first.back() > chartOf.size())
    return static_cast<std::uint32_t>(charts.size());
  for (std::size_t t = 0; t < chartOf.size(); ++t) {
    if (chartOf[t] == kNone) continue;
    const Chart& chart = charts[chartOf[t]];
    const auto [across, along] = grid[chartOf[t]];
    Vec2f centre{};
    for (std::size_t k = 0; k < 3; ++k) {
      centre.x += mesh.uvs[mesh.indices[3 * t + k]].x / 3;
      centre.y += mesh.uvs[mesh.indices[3 * t + k]].y / 3;
    }
    const auto piece = [](float x, float lo, float hi, std::uint32_t n) {
      const double f = hi > lo ? (x - lo) / (hi - lo) : 0.0;
      return std::min(n - 1, static_cast<std::uint32_t>(std::max(0.0, f * n)));
    };
    chartOf[t] = static_cast<std::uint32_t>(first[chartOf[t]]) +
                 piece(centre.y, chart.vmin, chart.vmax, along) * across +
                 piece(centre.x, chart.umin, chart.umax, across);
  }
  // Pieces no triangle fell in are left out of the numbering.
  std::vector<std::uint32_t> renumber(first.back(), kNone);
  std::uint32_t count = 0;
  for (std::uint32_t& c : chartOf) {
    if (c == kNone) continue;
    if (renumber[c] == kNone) renumber[c] = count++;
    c = renumber[c];
  }
  charts = describeCharts(mesh, table, chartOf, count);
  return count;
}

// The chart's rectangle at the tile's level, or the first coarser level whose rectangle fits a
// page (a chart wider than a page: a texture repeated many times over one surface).
bool placeInLevel(Chart& c, const TexturePyramid& pyramid, std::uint32_t level,
                  const AtlasOptions& options) {
  const std::uint32_t top = pyramid.levels(c.image) - 1;
  for (c.level = std::min(level, top);; ++c.level) {
    const double w = pyramid.width(c.image, c.level), h = pyramid.height(c.image, c.level);
    const double g = options.gutter;
    // (Work files are checked finite; a texture repeated a million times is no chart to copy.)
    const auto bounded = [](float x) { return std::clamp(static_cast<double>(x), -1e6, 1e6); };
    c.x0 = static_cast<std::int64_t>(std::floor(bounded(c.umin) * w - g));
    c.y0 = static_cast<std::int64_t>(std::floor(bounded(c.vmin) * h - g));
    const double x1 = std::ceil(bounded(c.umax) * w + g), y1 = std::ceil(bounded(c.vmax) * h + g);
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

// Copies the page's charts' texels from the pyramid into it.
Status bakeCharts(const std::vector<Chart>& charts, std::size_t p, const TextureTable& table,
                  const TexturePyramid& pyramid, Image& page, std::vector<std::uint8_t>& mask) {
  std::vector<std::uint8_t> texels;
  for (const Chart& c : charts) {
    if (c.page != p) continue;
    const Material& material = table.materials[c.material];
    texels.resize(std::size_t{c.w} * c.h * 4);
    LODFORGE_TRY(pyramid.read(c.image, c.level, c.x0, c.y0, c.w, c.h, material.wrapS,
                              material.wrapT, texels.data()));
    for (std::uint32_t row = 0; row < c.h; ++row) {
      const std::size_t at = std::size_t{c.ay + row} * page.width + c.ax;
      std::copy_n(texels.data() + 4 * std::size_t{row} * c.w, 4 * std::size_t{c.w},
                  page.rgba.data() + 4 * at);
      std::fill_n(mask.data() + at, c.w, std::uint8_t{1});
    }
  }
  return {};
}

}  // namespace

// The tile's vertices as the atlas needs them: a vertex of several charts (where a large chart
// was split) once per chart, each extra one a copy of its source vertex appended after the
// mesh's; the triangles over them.
void splitSharedVertices(const MeshPart& mesh, std::span<const std::uint32_t> chartOf,
                         TileAtlas& atlas) {
  std::vector<std::uint32_t> owner(mesh.vertexCount(), kNone);  // the chart a vertex went to
  std::unordered_map<std::uint64_t, std::uint32_t> copies;      // (vertex, chart) -> copy
  atlas.indices.assign(mesh.indices.begin(), mesh.indices.end());
  for (std::uint32_t v = 0; v < mesh.vertexCount(); ++v) atlas.vertexSource.push_back(v);
  for (std::size_t t = 0; t < chartOf.size(); ++t) {
    if (chartOf[t] == kNone) continue;
    for (std::size_t k = 0; k < 3; ++k) {
      std::uint32_t& v = atlas.indices[3 * t + k];
      if (owner[v] == kNone) owner[v] = chartOf[t];
      if (owner[v] == chartOf[t]) continue;
      const std::uint64_t key = (std::uint64_t{v} << 32) | chartOf[t];
      const auto [it, added] =
          copies.try_emplace(key, static_cast<std::uint32_t>(atlas.vertexSource.size()));
      if (added) atlas.vertexSource.push_back(v);
      v = it->second;
    }
  }
}

TileAtlas layoutTileAtlas(const MeshPart& mesh, const TextureTable& table,
                          const TexturePyramid& pyramid, std::uint32_t level,
                          const AtlasOptions& options) {
  assert(mesh.uvs.size() == mesh.vertexCount() && mesh.materials.size() == mesh.vertexCount());
  assert(options.maxSize >= 16 + 2 * options.gutter);
  TileAtlas atlas;
  std::uint32_t count = 0;
  std::vector<std::uint32_t> chartOf = chartOfTriangle(mesh, table, count);
  std::vector<Chart> charts = describeCharts(mesh, table, chartOf, count);
  count = splitLargeCharts(mesh, table, pyramid, level, options, charts, chartOf);
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
  for (const PageSize& size : sizes)
    atlas.pages.push_back({size.material, size.width, size.height, {}});
  splitSharedVertices(mesh, chartOf, atlas);
  // Texture coordinates into the pages: texel for texel of the chart's level.
  atlas.uvs.assign(atlas.vertexSource.size(), Vec2f{});
  atlas.pageOf.assign(atlas.vertexSource.size(), kNone);
  for (std::size_t t = 0; t < chartOf.size(); ++t) {
    if (chartOf[t] == kNone) continue;
    const Chart& c = charts[chartOf[t]];
    const AtlasPage& page = atlas.pages[c.page];
    const double w = pyramid.width(c.image, c.level), h = pyramid.height(c.image, c.level);
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = atlas.indices[3 * t + k];
      const Vec2f uv = mesh.uvs[atlas.vertexSource[v]];
      atlas.uvs[v] = {
          static_cast<float>((uv.x * w - static_cast<double>(c.x0) + c.ax) / page.width),
          static_cast<float>((uv.y * h - static_cast<double>(c.y0) + c.ay) / page.height)};
      atlas.pageOf[v] = c.page;
    }
  }
  atlas.layout = std::move(charts);
  return atlas;
}

Status bakeAtlasPage(TileAtlas& atlas, std::size_t page, const TextureTable& table,
                     const TexturePyramid& pyramid) {
  AtlasPage& p = atlas.pages[page];
  p.image = Image(p.width, p.height);
  std::vector<std::uint8_t> mask(p.image.pixelCount(), 0);
  LODFORGE_TRY(bakeCharts(atlas.layout, page, table, pyramid, p.image, mask));
  fillEmptyTexels(p.image, mask);
  return {};
}

Result<TileAtlas> bakeTileAtlas(const MeshPart& mesh, const TextureTable& table,
                                const TexturePyramid& pyramid, std::uint32_t level,
                                const AtlasOptions& options) {
  TileAtlas atlas = layoutTileAtlas(mesh, table, pyramid, level, options);
  for (std::size_t p = 0; p < atlas.pages.size(); ++p)
    LODFORGE_TRY(bakeAtlasPage(atlas, p, table, pyramid));
  return atlas;
}

namespace {

// A level of the fill pyramid: each texel the mean colour of the kept texels below it and how
// many there were (saturating: a weight, not a count). 4 bytes a texel, at half the size of the
// level below: the whole pyramid takes 4/3 of a byte per page texel.
struct FillLevel {
  std::uint32_t w = 0, h = 0;
  std::vector<std::array<std::uint8_t, 4>> texels;  // r, g, b, weight
};

// Pull: the level above `fine`, from a level given as colours and weights.
template <class Fine>
FillLevel pull(std::uint32_t w, std::uint32_t h, Fine&& fine) {
  FillLevel coarse{(w + 1) / 2, (h + 1) / 2, {}};
  coarse.texels.resize(std::size_t{coarse.w} * coarse.h);
  for (std::uint32_t y = 0; y < coarse.h; ++y)
    for (std::uint32_t x = 0; x < coarse.w; ++x) {
      std::uint32_t sum[3] = {0, 0, 0}, weight = 0;
      for (std::uint32_t dy = 0; dy < 2; ++dy)
        for (std::uint32_t dx = 0; dx < 2; ++dx) {
          if (2 * x + dx >= w || 2 * y + dy >= h) continue;
          const std::array<std::uint8_t, 4> t = fine(2 * x + dx, 2 * y + dy);
          for (std::size_t c = 0; c < 3; ++c) sum[c] += std::uint32_t{t[c]} * t[3];
          weight += t[3];
        }
      std::array<std::uint8_t, 4>& out = coarse.texels[std::size_t{y} * coarse.w + x];
      for (std::size_t c = 0; c < 3; ++c)
        out[c] = weight > 0 ? static_cast<std::uint8_t>((sum[c] + weight / 2) / weight) : 0;
      out[3] = static_cast<std::uint8_t>(std::min<std::uint32_t>(weight, 255));
    }
  return coarse;
}

}  // namespace

void fillEmptyTexels(Image& image, std::vector<std::uint8_t>& mask) {
  assert(mask.size() == image.pixelCount());
  if (image.pixelCount() == 0) return;
  std::vector<FillLevel> levels;
  levels.push_back(pull(image.width, image.height, [&](std::uint32_t x, std::uint32_t y) {
    const std::size_t i = std::size_t{y} * image.width + x;
    const std::uint8_t* p = &image.rgba[4 * i];
    return std::array<std::uint8_t, 4>{p[0], p[1], p[2], static_cast<std::uint8_t>(mask[i] != 0)};
  }));
  while (levels.back().w > 1 || levels.back().h > 1) {
    const FillLevel& fine = levels.back();
    levels.push_back(pull(fine.w, fine.h, [&fine](std::uint32_t x, std::uint32_t y) {
      return fine.texels[std::size_t{y} * fine.w + x];
    }));
  }
  // Push: an empty texel takes the (filled) texel above it, from the top down.
  for (std::size_t l = levels.size() - 1; l-- > 0;) {
    FillLevel& fine = levels[l];
    const FillLevel& coarse = levels[l + 1];
    for (std::uint32_t y = 0; y < fine.h; ++y)
      for (std::uint32_t x = 0; x < fine.w; ++x) {
        std::array<std::uint8_t, 4>& t = fine.texels[std::size_t{y} * fine.w + x];
        if (t[3] == 0) t = coarse.texels[std::size_t{y / 2} * coarse.w + x / 2];
        t[3] = 1;
      }
  }
  const FillLevel& first = levels.front();
  for (std::uint32_t y = 0; y < image.height; ++y)
    for (std::uint32_t x = 0; x < image.width; ++x) {
      const std::size_t i = std::size_t{y} * image.width + x;
      if (mask[i] != 0) continue;
      const std::array<std::uint8_t, 4>& t = first.texels[std::size_t{y / 2} * first.w + x / 2];
      std::copy_n(t.data(), 3, &image.rgba[4 * i]);
      image.rgba[4 * i + 3] = 255;
      mask[i] = 1;
    }
}

}  // namespace lodforge
