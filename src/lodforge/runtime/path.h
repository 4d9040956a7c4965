// Camera paths for the runtime benchmark and tests: an orbit around the model, a fly-through
// along its longest horizontal axis, and recorded paths read from (and written to) JSON.
//
// Path JSON (model coordinates, the same units and frame as the input model; z is up unless a
// frame says otherwise):
//   { "viewport": [1280, 720], "fovY": 60,
//     "frames": [ { "position": [x, y, z], "target": [x, y, z], "up": [0, 0, 1],
//                   "fovY": 60, "near": 0.01, "far": 1000 }, ... ] }
// "viewport", "fovY" (degrees), "up", "near" and "far" are optional; a frame's own values
// override the path's.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/runtime/camera.h"

namespace lodforge {

struct PathOptions {
  std::size_t frames = 120;
  std::uint32_t width = 1280, height = 720;
  double fovYDegrees = 60.0;
};

// Cameras in the coordinates of `bounds` (for a package: relative to its origin).
std::vector<Camera> orbitPath(const Aabbd& bounds, const PathOptions& options);
std::vector<Camera> flyThroughPath(const Aabbd& bounds, const PathOptions& options);
// The orbit's directions round the centre of `bounds`, each frame as near as keeps every one of
// `points` (the corners of the objects' boxes; none: of `bounds`) in the middle 90 % of the
// frame: the model fills the picture from every side, whatever its shape (`render`'s default;
// `orbit` keeps a fixed radius, 0.9 × the diagonal, for timings comparable across models).
std::vector<Camera> framedOrbitPath(const Aabbd& bounds, std::span<const Vec3d> points,
                                    const PathOptions& options);

// Reads a recorded path; positions are in model coordinates and `origin` (the package origin)
// is subtracted. Frames without near/far get planes fitted to `bounds` (origin-relative).
// Errors name the file and the byte or the frame.
Result<std::vector<Camera>> readCameraPath(const std::string& path, Vec3d origin,
                                           const Aabbd& bounds);
Status writeCameraPath(const std::string& path, const std::vector<Camera>& cameras, Vec3d origin);

// Near and far planes that suit a model of this size seen from anywhere near it.
void fitClipPlanes(Camera& camera, const Aabbd& bounds);

}  // namespace lodforge
