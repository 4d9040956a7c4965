// `lodforge generate scan`: one connected scanned surface of exactly N triangles (a regular grid
// over the Terrain, with holes and an overhanging cliff), streamed to a binary PLY row by row so
// memory stays flat up to 10^9 triangles. With a texture, photo-like JPEG atlases beside it
// (scan_texture.h) instead of vertex colours.
#pragma once

#include <cstdint>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/generate/stats.h"

namespace lodforge {

struct ScanOptions {
  std::uint64_t triangles = 1'000'000;
  std::uint64_t seed = 1;
  double width = 1000.0;  // metres across; the depth follows from the triangle count (3:2)
  // Texture atlases of this many texels a side (0: none, vertex colours instead), `atlases` of
  // them over the scan (scan_texture.h).
  std::uint32_t textureSize = 0;
  std::uint32_t atlases = 16;
};

Result<GenerateStats> generateScan(const ScanOptions& options, const std::string& path);

}  // namespace lodforge
