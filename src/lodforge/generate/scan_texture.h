// Photo-like texture atlases for `generate scan --texture`: the scan's grid cut into a grid of
// regions, each drawn into a square image of its own (ground colours by large-scale noise,
// detail down to the texel by fine noise) and written as a JPEG beside the PLY, which names
// them in "comment TextureFile" lines and gives each face its region (texnumber) and corner
// coordinates in it (texcoord): MeshLab's and OpenDroneMap's textured PLY.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "lodforge/core/image.h"
#include "lodforge/core/status.h"

namespace lodforge {

// `atlases` regions over a grid of `columns` x `rows` cells: as square a grid of regions as
// the count allows, each a range of whole cells (so every corner's coordinate is in [0, 1]).
struct ScanAtlasLayout {
  std::uint32_t across = 1, along = 1;
  std::uint64_t columns = 1, rows = 1;

  static ScanAtlasLayout of(std::uint32_t atlases, std::uint64_t columns, std::uint64_t rows);
  std::uint32_t count() const { return across * along; }
  // The region of a cell.
  std::uint32_t regionOf(std::uint64_t column, std::uint64_t row) const;
  // A region's cells: first column, end column, first row, end row.
  std::array<std::uint64_t, 4> cells(std::uint32_t region) const;
};

// Region `region`'s image: `size` texels a side over its cells (`cell` metres each).
Image drawScanAtlas(std::uint64_t seed, const ScanAtlasLayout& layout, std::uint32_t region,
                    double cell, std::uint32_t size);

// "scan_atlas_03.jpg" beside "scan.ply": the name the PLY's comment gives and the file.
std::string scanAtlasName(const std::string& plyPath, std::uint32_t region);

// Whether an atlas may be written at `path`: nothing there, or an atlas of ours (kUsage
// naming it otherwise).
Status checkScanAtlasPlace(const std::string& path);
// Writes the region's image as a JPEG (quality 90, marked as lodforge's so that a later run
// may replace it; a file there that is not one of ours is refused).
Status writeScanAtlas(const Image& image, const std::string& path);

}  // namespace lodforge
