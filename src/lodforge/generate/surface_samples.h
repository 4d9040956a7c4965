// `lodforge generate points --from MESH`: N points spread by area over a mesh's triangles — a
// cloud whose true surface is known, to measure a reconstruction against it (`compare`). Each
// point carries its triangle's normal (the mesh's vertex normals interpolated where it has them)
// and moves along it by Gaussian noise. Deterministic for a seed whatever the thread count.
#pragma once

#include <cstdint>
#include <string>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"
#include "lodforge/generate/stats.h"

namespace lodforge {

struct SurfaceSampleOptions {
  std::uint64_t points = 1'000'000;
  std::uint64_t seed = 1;
  double noise = 0;  // standard deviation along the normal, a share of the bounding-box diagonal
};

// Writes the samples of `model`'s triangles (every object's) as a binary PLY with normals.
// Refused (kBadInput) when the model has no triangle of non-zero area.
Result<GenerateStats> sampleSurface(const Model& model, const SurfaceSampleOptions& options,
                                    const std::string& path);

}  // namespace lodforge
