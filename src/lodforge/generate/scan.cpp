#include "lodforge/generate/scan.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include <tbb/parallel_for.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/generate/scan_texture.h"
#include "lodforge/generate/terrain.h"
#include "lodforge/io/mesh/ply_writer.h"

namespace lodforge {

namespace {

constexpr std::uint32_t kUnused = ~0u;
// A block holds about this many grid points (positions, normals, colours: ~40 bytes each), so
// memory stays flat however wide the grid is.
constexpr std::uint64_t kPointsPerBlock = 1 << 18;

// A triangle of a cell row: corners as (column, 0 = lower vertex row, 1 = upper vertex row).
struct Corner {
  std::uint32_t column;
  std::uint8_t upper;
};
using CellTriangle = std::array<Corner, 3>;

// Walks the grid one vertex row at a time: which cells are present (not in a hole, and before
// the N-th triangle), which vertices they use, and the vertices' global indices. Both passes
// (counting, then writing) run the same walk, so they agree exactly.
class GridWalk {
 public:
  GridWalk(const Terrain& terrain, std::uint64_t columns, double cell, std::uint64_t triangles)
      : terrain_(terrain),
        columns_(columns),
        cell_(cell),
        triangles_(triangles),
        lowerIndex_(columns + 1, kUnused),
        upperIndex_(columns + 1, kUnused) {}

  // Advances to the next vertex row; false when the grid is finished. Afterwards rowIndex()
  // holds the row's vertex indices and finishedTriangles() the triangles of the cell row below,
  // whose vertices all have indices now.
  bool step() {
    if (row_ > 0 && below_.empty() && emitted_ >= triangles_) return false;
    current_.clear();
    cellRow(row_, current_);
    // Vertex row `row_` is the top of cell row row_-1 and the bottom of cell row row_.
    std::swap(lowerIndex_, upperIndex_);  // the old upper row is now the row below
    std::fill(upperIndex_.begin(), upperIndex_.end(), kUnused);
    for (const CellTriangle& t : below_) {
      for (const Corner& c : t)
        if (c.upper) upperIndex_[c.column] = 0;
    }
    for (const CellTriangle& t : current_) {
      for (const Corner& c : t)
        if (!c.upper) upperIndex_[c.column] = 0;
    }
    for (std::uint32_t& index : upperIndex_) {
      if (index == 0) index = static_cast<std::uint32_t>(vertexCount_++);
    }
    finished_.clear();
    for (const CellTriangle& t : below_) {
      std::array<std::uint32_t, 3> tri{};
      for (int k = 0; k < 3; ++k) {
        const Corner& c = t[static_cast<std::size_t>(k)];
        tri[static_cast<std::size_t>(k)] = c.upper ? upperIndex_[c.column] : lowerIndex_[c.column];
      }
      finished_.insert(finished_.end(), tri.begin(), tri.end());
    }
    std::swap(below_, current_);
    ++row_;
    return true;
  }

  std::uint64_t row() const { return row_ - 1; }  // the vertex row step() just produced
  // The cells of finishedTriangles(), in their order: cell row row() - 1.
  const std::vector<CellTriangle>& finishedCells() const { return current_; }
  const std::vector<std::uint32_t>& rowIndex() const { return upperIndex_; }
  const std::vector<std::uint32_t>& finishedTriangles() const { return finished_; }
  std::uint64_t vertexCount() const { return vertexCount_; }

 private:
  void cellRow(std::uint64_t row, std::vector<CellTriangle>& out) {
    for (std::uint32_t c = 0; c < columns_ && emitted_ < triangles_; ++c) {
      const double u = (c + 0.5) * cell_, v = (static_cast<double>(row) + 0.5) * cell_;
      if (terrain_.inHole(u, v)) continue;
      const Corner v00{c, 0}, v10{c + 1, 0}, v01{c, 1}, v11{c + 1, 1};
      // Alternate the diagonal so the triangulation has no preferred direction.
      const bool even = (c + row) % 2 == 0;
      out.push_back(even ? CellTriangle{v00, v10, v11} : CellTriangle{v00, v10, v01});
      if (++emitted_ == triangles_) break;  // odd N: the last cell keeps one triangle
      out.push_back(even ? CellTriangle{v00, v11, v01} : CellTriangle{v10, v11, v01});
      ++emitted_;
    }
  }

  const Terrain& terrain_;
  std::uint64_t columns_;
  double cell_;
  std::uint64_t triangles_;
  std::uint64_t emitted_ = 0;
  std::uint64_t row_ = 0;
  std::uint64_t vertexCount_ = 0;
  std::vector<CellTriangle> below_, current_;
  std::vector<std::uint32_t> lowerIndex_, upperIndex_;
  std::vector<std::uint32_t> finished_;
};

// Positions, normals and colours of a block of vertex rows, computed in parallel. Positions
// are sampled one column and one row beyond each side so normals are central differences.
class RowBlock {
 public:
  RowBlock(const Terrain& terrain, std::uint64_t columns, double cell)
      : terrain_(terrain), columns_(columns), cell_(cell) {}

  void compute(std::uint64_t firstRow, std::uint64_t rows) {
    first_ = firstRow;
    rows_ = rows;
    const std::size_t stride = columns_ + 3;
    grid_.resize((rows + 2) * stride);
    tbb::parallel_for(std::size_t{0}, rows + 2, [&](std::size_t r) {
      const double v = (static_cast<double>(firstRow) + static_cast<double>(r) - 1.0) * cell_;
      for (std::size_t c = 0; c < stride; ++c) {
        grid_[r * stride + c] = terrain_.position((static_cast<double>(c) - 1.0) * cell_, v);
      }
    });
    normals_.resize(rows * (columns_ + 1));
    colors_.resize(rows * (columns_ + 1));
    tbb::parallel_for(std::size_t{0}, static_cast<std::size_t>(rows), [&](std::size_t r) {
      for (std::size_t c = 0; c <= columns_; ++c) {
        const Vec3d du = at(r + 1, c + 2) - at(r + 1, c);
        const Vec3d dv = at(r + 2, c + 1) - at(r, c + 1);
        const Vec3d n = normalizeOr(cross(du, dv), Vec3d{0, 0, 1});
        const std::size_t i = r * (columns_ + 1) + c;
        normals_[i] = toFloat(n);
        colors_[i] = terrain_.color(static_cast<double>(c) * cell_,
                                    static_cast<double>(first_ + r) * cell_, at(r + 1, c + 1), n);
      }
    });
  }
  Vec3d position(std::uint64_t row, std::uint64_t column) const {
    return at(row - first_ + 1, column + 1);
  }
  Vec3f normal(std::uint64_t row, std::uint64_t column) const {
    return normals_[(row - first_) * (columns_ + 1) + column];
  }
  Rgba8 color(std::uint64_t row, std::uint64_t column) const {
    return colors_[(row - first_) * (columns_ + 1) + column];
  }
  bool holds(std::uint64_t row) const { return row >= first_ && row < first_ + rows_; }

 private:
  Vec3d at(std::size_t r, std::size_t c) const { return grid_[r * (columns_ + 3) + c]; }
  const Terrain& terrain_;
  std::uint64_t columns_;
  double cell_;
  std::uint64_t first_ = 0, rows_ = 0;
  std::vector<Vec3d> grid_;
  std::vector<Vec3f> normals_;
  std::vector<Rgba8> colors_;
};

// The atlases, drawn and written one at a time, and the PLY comments that name them.
Status writeAtlases(const ScanOptions& options, const ScanAtlasLayout& atlases, double cell,
                    const std::string& path, std::vector<std::string>& comments) {
  Progress progress("scan: textures", atlases.count());
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  // Every place checked before any atlas is drawn: a refusal leaves nothing written.
  for (std::uint32_t region = 0; region < atlases.count(); ++region)
    LODFORGE_TRY(checkScanAtlasPlace((folder / scanAtlasName(path, region)).string()));
  for (std::uint32_t region = 0; region < atlases.count(); ++region) {
    LODFORGE_TRY(checkCancelled());
    const std::string name = scanAtlasName(path, region);
    const Image image = drawScanAtlas(options.seed, atlases, region, cell, options.textureSize);
    LODFORGE_TRY(writeScanAtlas(image, (folder / name).string()));
    comments.push_back("TextureFile " + name);
    progress.advance(1);
  }
  progress.finish();
  return {};
}

// Each finished triangle's atlas (the region of its cell) and its corners' coordinates in it.
void cornerTextures(const GridWalk& walk, const ScanAtlasLayout& atlases,
                    std::vector<Vec2f>& cornerUvs, std::vector<std::uint32_t>& textures) {
  cornerUvs.clear();
  textures.clear();
  const std::uint64_t cellRow = walk.row() - 1;
  for (const CellTriangle& t : walk.finishedCells()) {
    const std::uint32_t column = std::min({t[0].column, t[1].column, t[2].column});
    const std::uint32_t region = atlases.regionOf(column, cellRow);
    const std::array<std::uint64_t, 4> cells = atlases.cells(region);
    textures.push_back(region);
    for (const Corner& c : t) {
      const double u =
          static_cast<double>(c.column - cells[0]) / static_cast<double>(cells[1] - cells[0]);
      const double v = static_cast<double>(cellRow + c.upper - cells[2]) /
                       static_cast<double>(cells[3] - cells[2]);
      cornerUvs.push_back({static_cast<float>(u), static_cast<float>(v)});
    }
  }
}

}  // namespace

Result<GenerateStats> generateScan(const ScanOptions& options, const std::string& path) {
  if (options.triangles == 0) return Error{ErrorKind::kUsage, "a scan needs at least one triangle"};
  if (fileExtension(path) != "ply")
    return Error{ErrorKind::kUsage, fmt::format("{}: the scan generator writes .ply", path)};
  // Cells in a 3:2 grid; rows grow past the estimate by what the holes take.
  const std::uint64_t cells = (options.triangles + 1) / 2;
  const auto columns = std::max<std::uint64_t>(
      1, static_cast<std::uint64_t>(std::sqrt(1.5 * static_cast<double>(cells))));
  const double cell = options.width / static_cast<double>(columns);
  const double depth = std::ceil(static_cast<double>(cells) / static_cast<double>(columns)) * cell;
  const Terrain terrain(options.seed, options.width, depth, cell);

  // Pass 1: count the vertices the triangles use (cheap: no heights evaluated).
  std::uint64_t vertexCount = 0, cellRows = 0;
  {
    GridWalk walk(terrain, columns, cell, options.triangles);
    while (walk.step()) cellRows = walk.row();
    vertexCount = walk.vertexCount();
  }
  if (vertexCount > 0xFFFFFFFFull) {
    return Error{ErrorKind::kLimit,
                 fmt::format("{} vertices exceed PLY's 32-bit indices", vertexCount)};
  }

  const bool textured = options.textureSize > 0;
  const ScanAtlasLayout atlases = ScanAtlasLayout::of(options.atlases, columns, cellRows);
  PlyLayout layout;
  layout.vertexCount = vertexCount;
  layout.faceCount = options.triangles;
  layout.normals = true;
  layout.colors = !textured;
  layout.faceUvs = textured;
  layout.comments = {fmt::format("lodforge generate scan --triangles {} --seed {}",
                                 options.triangles, options.seed)};
  if (textured) LODFORGE_TRY(writeAtlases(options, atlases, cell, path, layout.comments));
  Result<PlyWriter> writer = PlyWriter::create(path, layout);
  if (!writer) return writer.status();

  // Pass 2: the same walk, with geometry computed a block of rows at a time.
  GridWalk walk(terrain, columns, cell, options.triangles);
  RowBlock block(terrain, columns, cell);
  Progress progress("scan", options.triangles);
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<Vec2f> cornerUvs;
  std::vector<std::uint32_t> textures;
  while (walk.step()) {
    const std::uint64_t row = walk.row();
    if (!block.holds(row)) {
      LODFORGE_TRY(checkCancelled());
      block.compute(row, std::clamp<std::uint64_t>(kPointsPerBlock / (columns + 3), 2, 64));
    }
    positions.clear();
    normals.clear();
    colors.clear();
    const std::vector<std::uint32_t>& index = walk.rowIndex();
    for (std::uint64_t c = 0; c < index.size(); ++c) {
      if (index[c] == kUnused) continue;
      positions.push_back(toFloat(block.position(row, c)));
      normals.push_back(block.normal(row, c));
      if (!textured) colors.push_back(block.color(row, c));
    }
    LODFORGE_TRY(writer->writeVertices(positions, normals, colors));
    if (textured) cornerTextures(walk, atlases, cornerUvs, textures);
    LODFORGE_TRY(writer->writeTriangles(walk.finishedTriangles(), {}, cornerUvs, textures));
    progress.advance(walk.finishedTriangles().size() / 3);
  }
  progress.finish();
  const std::uint64_t bytes = writer->fileBytes();
  LODFORGE_TRY(writer->finish());
  return GenerateStats{1, vertexCount, options.triangles, bytes};
}

}  // namespace lodforge
