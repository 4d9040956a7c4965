// The surface options `reconstruct` and `tiles --surface` share (docs/surface.md); the chunk size
// is each command's own (voxels for reconstruct, model units for tiles).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "lodforge/core/status.h"
#include "lodforge/surface/reconstruct.h"

namespace lodforge::cli {

// reconstruct's --decimate when not given: on the horse (docs/BENCHMARKS.md) 0.32x PoissonRecon
// depth 9's triangles, the surface within 0.16 voxels of the undecimated one.
constexpr double kReconstructDecimateVoxels = 0.02;

struct SurfaceCommand {
  ReconstructOptions reconstruct;
  std::string orient = "auto";
};

// --voxel --radius --min-points --orient --min-triangles --decimate.
void addSurfaceOptions(CLI::App& sub, SurfaceCommand& options);

// The options for `input`: --orient auto turns normals up for LAS and LAZ (airborne lidar) and
// by propagation otherwise; a bad --orient is a usage error.
Result<ReconstructOptions> surfaceOptions(const SurfaceCommand& options, const std::string& input);

}  // namespace lodforge::cli
