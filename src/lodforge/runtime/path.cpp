#include "lodforge/runtime/path.h"

#include <cmath>
#include <numbers>
#include <optional>

#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"

namespace lodforge {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr std::uint64_t kMaxPathBytes = std::uint64_t{256} << 20;

double diagonal(const Aabbd& bounds) {
  const double d = length(bounds.size());
  return d > 0 && std::isfinite(d) ? d : 1.0;
}

// Parameter of frame i in [0, 1): a closed orbit must not repeat its first frame at the end.
double phase(std::size_t i, std::size_t frames) {
  return frames == 0 ? 0.0 : static_cast<double>(i) / static_cast<double>(frames);
}

Error frameError(const std::string& file, std::size_t frame, std::string_view what) {
  return badInput(file, fmt::format("frame {}: {}", frame, what));
}

// A 3-vector of finite numbers, or nothing.
std::optional<Vec3d> vec3(const nlohmann::json& value) {
  if (!value.is_array() || value.size() != 3) return std::nullopt;
  Vec3d v;
  for (int k = 0; k < 3; ++k) {
    if (!value[static_cast<std::size_t>(k)].is_number()) return std::nullopt;
    v[k] = value[static_cast<std::size_t>(k)].get<double>();
  }
  return isFinite(v) ? std::optional<Vec3d>(v) : std::nullopt;
}

// An optional number field: nothing when absent, NaN when present but not a finite number (so
// every range check below refuses it).
std::optional<double> numberField(const nlohmann::json& object, const char* key) {
  if (!object.contains(key)) return std::nullopt;
  const nlohmann::json& value = object[key];
  const double x = value.is_number() ? value.get<double>() : std::nan("");
  return std::isfinite(x) ? x : std::nan("");
}

bool isDegrees(double x) {
  return x > 0 && x < 180;
}

}  // namespace

void fitClipPlanes(Camera& camera, const Aabbd& bounds) {
  // A 24-bit depth buffer resolves far/near ratios up to ~1e6 comfortably.
  const double d = diagonal(bounds);
  camera.nearPlane = d * 1e-5;
  camera.farPlane = d * 10.0 + length(camera.position - bounds.center());
}

namespace {

// The orbit's frames: round the centre of `bounds` 25° above it, each `distance(toEye)` from
// the centre along the unit direction to the eye.
template <class Distance>
std::vector<Camera> orbitFrames(const Aabbd& bounds, const PathOptions& options,
                                const Distance& distance) {
  const Vec3d centre = bounds.center();
  const double elevation = 25.0 * kDegree;
  std::vector<Camera> cameras;
  cameras.reserve(options.frames);
  for (std::size_t i = 0; i < options.frames; ++i) {
    const double azimuth = 2.0 * std::numbers::pi * phase(i, options.frames);
    const Vec3d toEye{std::cos(elevation) * std::cos(azimuth),
                      std::cos(elevation) * std::sin(azimuth), std::sin(elevation)};
    const Vec3d eye = centre + toEye * distance(toEye);
    Camera camera =
        Camera::lookAt(eye, centre, {0, 0, 1}, options.fovYDegrees, options.width, options.height);
    fitClipPlanes(camera, bounds);
    cameras.push_back(camera);
  }
  return cameras;
}

// The distance from the centre of `bounds` along `toEye` (unit) at which every one of `points`
// lies in the middle `fill` of the frame: per point, the depth its offset from the centre needs
// in x and in y (x ≤ fill · tan(half angle) · depth).
double framingDistance(const Aabbd& bounds, std::span<const Vec3d> points, Vec3d toEye,
                       const PathOptions& options, double fill) {
  const Vec3d forward = toEye * -1.0;
  const Vec3d right = normalizeOr(cross(forward, Vec3d{0, 0, 1}), Vec3d{1, 0, 0});
  const Vec3d up = cross(right, forward);
  const double tanY = std::tan(options.fovYDegrees * kDegree / 2);
  const double tanX = tanY * static_cast<double>(options.width) /
                      static_cast<double>(std::max<std::uint32_t>(1, options.height));
  double distance = 1e-3 * diagonal(bounds);
  for (const Vec3d& point : points) {
    const Vec3d c = point - bounds.center();
    const double nearer = dot(c, toEye);
    distance = std::max({distance, nearer + std::abs(dot(c, right)) / (fill * tanX),
                         nearer + std::abs(dot(c, up)) / (fill * tanY)});
  }
  return distance;
}

}  // namespace

std::vector<Camera> orbitPath(const Aabbd& bounds, const PathOptions& options) {
  const double radius = 0.9 * diagonal(bounds);
  return orbitFrames(bounds, options, [radius](Vec3d) { return radius; });
}

std::vector<Camera> framedOrbitPath(const Aabbd& bounds, std::span<const Vec3d> points,
                                    const PathOptions& options) {
  std::vector<Vec3d> corners;
  if (points.empty()) {
    for (int i = 0; i < 8; ++i) corners.push_back(bounds.corner(i));
    points = corners;
  }
  return orbitFrames(bounds, options, [&](Vec3d toEye) {
    return framingDistance(bounds, points, toEye, options, 0.9);
  });
}

std::vector<Camera> flyThroughPath(const Aabbd& bounds, const PathOptions& options) {
  // Along the longest horizontal axis at mid height, from 10 % before the model to 10 % past
  // it, swaying ±20° so that objects enter and leave the view from the sides too.
  const Vec3d size = bounds.size(), centre = bounds.center();
  const int axis = size.x >= size.y ? 0 : 1;
  Vec3d along{0, 0, 0}, side{0, 0, 0};
  along[axis] = 1;
  side[1 - axis] = 1;
  std::vector<Camera> cameras;
  cameras.reserve(options.frames);
  const std::size_t last = options.frames > 1 ? options.frames - 1 : 1;
  for (std::size_t i = 0; i < options.frames; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(last);
    Vec3d eye = centre;
    eye[axis] = bounds.min[axis] + (-0.1 + 1.2 * t) * size[axis];
    const double yaw = 20.0 * kDegree * std::sin(2.0 * std::numbers::pi * t);
    const Vec3d forward = along * std::cos(yaw) + side * std::sin(yaw);
    Camera camera = Camera::lookAt(eye, eye + forward, {0, 0, 1}, options.fovYDegrees,
                                   options.width, options.height);
    fitClipPlanes(camera, bounds);
    cameras.push_back(camera);
  }
  return cameras;
}

Result<std::vector<Camera>> readCameraPath(const std::string& path, Vec3d origin,
                                           const Aabbd& bounds) {
  auto text = readFileToString(path, kMaxPathBytes);
  if (!text) return text.status();
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(*text);
  } catch (const nlohmann::json::parse_error& e) {
    return badInputAtByte(path, e.byte, "the camera path is not valid JSON");
  }
  if (!document.is_object())
    return badInput(path, "a camera path is a JSON object with \"frames\"");
  std::uint32_t width = 1280, height = 720;
  if (document.contains("viewport")) {
    const auto& viewport = document["viewport"];
    if (!viewport.is_array() || viewport.size() != 2 || !viewport[0].is_number_unsigned() ||
        !viewport[1].is_number_unsigned() || viewport[0].get<std::uint64_t>() - 1 >= 16384 ||
        viewport[1].get<std::uint64_t>() - 1 >= 16384)
      return badInput(path, "\"viewport\" must be [width, height] in pixels, each 1..16384");
    width = viewport[0].get<std::uint32_t>();
    height = viewport[1].get<std::uint32_t>();
  }
  double fovY = 60.0;
  if (auto f = numberField(document, "fovY")) {
    if (!isDegrees(*f)) return badInput(path, "\"fovY\" must be degrees in (0, 180)");
    fovY = *f;
  }
  if (!document.contains("frames") || !document["frames"].is_array() || document["frames"].empty())
    return badInput(path, "\"frames\" must be a non-empty array");
  std::vector<Camera> cameras;
  const auto& frames = document["frames"];
  cameras.reserve(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto& frame = frames[i];
    if (!frame.is_object()) return frameError(path, i, "a frame is an object");
    const auto position = frame.contains("position") ? vec3(frame["position"]) : std::nullopt;
    const auto target = frame.contains("target") ? vec3(frame["target"]) : std::nullopt;
    if (!position || !target)
      return frameError(path, i,
                        "\"position\" and \"target\" must be arrays of three finite numbers");
    if (length(*target - *position) <= 0)
      return frameError(path, i, "\"target\" equals \"position\"");
    Vec3d up{0, 0, 1};
    if (frame.contains("up")) {
      const auto u = vec3(frame["up"]);
      if (!u || length(*u) <= 0) return frameError(path, i, "\"up\" must be a non-zero vector");
      up = *u;
    }
    double frameFov = fovY;
    if (auto f = numberField(frame, "fovY")) {
      if (!isDegrees(*f)) return frameError(path, i, "\"fovY\" must be degrees in (0, 180)");
      frameFov = *f;
    }
    Camera camera =
        Camera::lookAt(*position - origin, *target - origin, up, frameFov, width, height);
    fitClipPlanes(camera, bounds);
    const auto nearPlane = numberField(frame, "near"), farPlane = numberField(frame, "far");
    if (nearPlane && !(*nearPlane > 0))
      return frameError(path, i, "\"near\" must be a positive number");
    if (farPlane && !(*farPlane > 0))
      return frameError(path, i, "\"far\" must be a positive number");
    if (nearPlane) camera.nearPlane = *nearPlane;
    if (farPlane) camera.farPlane = *farPlane;
    if (camera.farPlane <= camera.nearPlane)
      return frameError(path, i, "\"far\" must exceed \"near\"");
    cameras.push_back(camera);
  }
  return cameras;
}

Status writeCameraPath(const std::string& path, const std::vector<Camera>& cameras, Vec3d origin) {
  nlohmann::json frames = nlohmann::json::array();
  for (const Camera& camera : cameras) {
    const Vec3d eye = camera.position + origin, target = eye + camera.forward;
    frames.push_back({{"position", {eye.x, eye.y, eye.z}},
                      {"target", {target.x, target.y, target.z}},
                      {"up", {camera.up.x, camera.up.y, camera.up.z}},
                      {"fovY", camera.fovY / kDegree},
                      {"near", camera.nearPlane},
                      {"far", camera.farPlane}});
  }
  nlohmann::json document = {{"frames", std::move(frames)}};
  if (!cameras.empty()) {
    document["viewport"] = {cameras.front().width, cameras.front().height};
    document["fovY"] = cameras.front().fovY / kDegree;
  }
  const std::string text = document.dump(1);
  auto file = OutputFile::create(path);
  if (!file) return file.status();
  LODFORGE_TRY(file->write(text.data(), text.size()));
  return file->commit();
}

}  // namespace lodforge
