// `lodforge generate points`: a scanned-surface point cloud of exactly N points (positions,
// normals, colours) sampled over the Terrain, written as a binary PLY in batches so memory stays
// flat. Deterministic for a seed whatever the thread count.
#pragma once

#include <cstdint>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/generate/stats.h"
#include "lodforge/io/points/point_extras.h"

namespace lodforge {

struct PointsOptions {
  std::uint64_t points = 1'000'000;
  std::uint64_t seed = 1;
  double width = 1000.0;  // metres; depth is 2/3 of it
  double noise = 0.005;   // metres of scanner noise along the normal
  // LAS only: extra bytes described by an Extra Bytes record (height above ground, echo width,
  // range, amplitude), as many scanner deliveries carry.
  bool extraBytes = false;
};

// The extra bytes `extraBytes` adds to each LAS record.
PointExtras generatedExtraBytes();

Result<GenerateStats> generatePoints(const PointsOptions& options, const std::string& path);

}  // namespace lodforge
