#include "surface_options.h"

#include <cstdio>

#include <fmt/format.h>

#include "cli.h"
#include "lodforge/core/file.h"

namespace lodforge::cli {

namespace {

// --orient: auto, propagate, up, or a viewpoint "X,Y,Z".
Result<NormalOptions> parseOrientation(const std::string& text, const std::string& input) {
  NormalOptions options;
  const std::string extension = fileExtension(input);
  if (text == "propagate" || (text == "auto" && extension != "las" && extension != "laz"))
    return options;
  if (text == "up" || text == "auto") {
    options.orientation = NormalOrientation::kUp;
    return options;
  }
  double x = 0, y = 0, z = 0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &extra) == 3) {
    options.orientation = NormalOrientation::kViewpoint;
    options.viewpoint = {x, y, z};
    return options;
  }
  return Error{
      ErrorKind::kUsage,
      fmt::format("--orient: \"{}\" is not auto, propagate, up or a viewpoint X,Y,Z", text)};
}

}  // namespace

void addSurfaceOptions(CLI::App& sub, SurfaceCommand& options) {
  sub.add_option("--voxel", options.reconstruct.voxel,
                 "Surface: voxel edge in the cloud's units, as `info` gives its bounds (feet for "
                 "a CRS in feet, also when the tiles are placed on Earth); 0 or left out: twice "
                 "the median point spacing")
      ->check(CLI::NonNegativeNumber);
  sub.add_option("--radius", options.reconstruct.distance.radius,
                 "Surface: points within this many voxels of a corner set its distance (default 3)")
      ->check(CLI::Range(0.5, 16.0));
  sub.add_option("--min-points", options.reconstruct.distance.minPoints,
                 "Surface: fewest points near a corner for a surface there (default 3)")
      ->check(CLI::Range(1, 1000));
  sub.add_option("--orient", options.orient,
                 "Surface, points without normals: auto (default: up for LAS/LAZ, else "
                 "propagate), propagate (by the neighbour graph: closed objects), up (+z: scans "
                 "of the ground) or towards a viewpoint X,Y,Z");
  addCountOption(sub, "--min-triangles", options.reconstruct.minTriangles,
                 "Surface: drop connected pieces with fewer triangles (default 0: keep all)");
  sub.add_option(
         "--decimate", options.reconstruct.decimateVoxels,
         fmt::format("Surface: thin each chunk's triangles by edge collapses whose removed "
                     "vertices lie within this many voxels of the surface that replaces "
                     "them (the surface itself moved up to 10x that on a scan; 0: keep every "
                     "triangle; reconstruct's default {}, tiles' 0)",
                     kReconstructDecimateVoxels))
      ->check(CLI::Range(0.0, 4.0));
}

Result<ReconstructOptions> surfaceOptions(const SurfaceCommand& options, const std::string& input) {
  ReconstructOptions reconstruct = options.reconstruct;
  Result<NormalOptions> normals = parseOrientation(options.orient, input);
  if (!normals) return normals.status();
  reconstruct.normals = *normals;
  return reconstruct;
}

}  // namespace lodforge::cli
