#include "lodforge/tiles/georeference.h"

#include <cmath>
#include <numbers>
#include <sstream>

#include <fmt/format.h>
#include <proj.h>

namespace lodforge {
namespace {

constexpr double kSemiMajor = 6378137.0;             // WGS84 a
constexpr double kFlattening = 1.0 / 298.257223563;  // WGS84 f
constexpr double kEccentricity2 = kFlattening * (2 - kFlattening);

double radians(double degrees) {
  return degrees * std::numbers::pi / 180;
}

// The rigid inverse: transpose the rotation, rotate the negated translation.
Mat4d inverseRigid(const Mat4d& m) {
  Mat4d out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.at(r, c) = m.at(c, r);
  for (int r = 0; r < 3; ++r) {
    double t = 0;
    for (int k = 0; k < 3; ++k) t -= m.at(k, r) * m.at(k, 3);
    out.at(r, 3) = t;
  }
  return out;
}

}  // namespace

Vec3d geodeticToEcef(const Geodetic& g) {
  const double lon = radians(g.longitude), lat = radians(g.latitude);
  const double n = kSemiMajor / std::sqrt(1 - kEccentricity2 * std::sin(lat) * std::sin(lat));
  return {(n + g.height) * std::cos(lat) * std::cos(lon),
          (n + g.height) * std::cos(lat) * std::sin(lon),
          (n * (1 - kEccentricity2) + g.height) * std::sin(lat)};
}

Mat4d eastNorthUpToEcef(const Geodetic& g) {
  const double lon = radians(g.longitude), lat = radians(g.latitude);
  const Vec3d east{-std::sin(lon), std::cos(lon), 0};
  const Vec3d north{-std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat)};
  const Vec3d up{std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)};
  const Vec3d origin = geodeticToEcef(g);
  Mat4d m;
  for (int r = 0; r < 3; ++r) {
    m.at(r, 0) = east[r];
    m.at(r, 1) = north[r];
    m.at(r, 2) = up[r];
    m.at(r, 3) = origin[r];
  }
  return m;
}

Result<Geodetic> parseOrigin(const std::string& text) {
  Geodetic g;
  char comma1 = 0, comma2 = 0;
  std::istringstream in(text);
  in >> g.longitude >> comma1 >> g.latitude >> comma2 >> g.height;
  if (!in || comma1 != ',' || comma2 != ',' || !in.eof() || std::abs(g.longitude) > 180 ||
      std::abs(g.latitude) > 90 || !std::isfinite(g.height))
    return Error{ErrorKind::kUsage,
                 fmt::format("--origin {}: expected LON,LAT,HEIGHT in degrees and metres, e.g. "
                             "8.5417,47.3769,408",
                             text)};
  return g;
}

struct CrsToLocal::Projection {
  PJ_CONTEXT* context = nullptr;
  PJ* toEcef = nullptr;
  ~Projection() {
    if (toEcef != nullptr) proj_destroy(toEcef);
    if (context != nullptr) proj_context_destroy(context);
  }
};

CrsToLocal::CrsToLocal(CrsToLocal&&) noexcept = default;
CrsToLocal& CrsToLocal::operator=(CrsToLocal&&) noexcept = default;
CrsToLocal::~CrsToLocal() = default;

Result<CrsToLocal> CrsToLocal::create(const std::string& crs, Vec3d sample) {
  CrsToLocal out;
  out.projection_ = std::make_unique<Projection>();
  Projection& p = *out.projection_;
  p.context = proj_context_create();
  proj_log_level(p.context, PJ_LOG_NONE);
  PJ* raw = proj_create_crs_to_crs(p.context, crs.c_str(), "EPSG:4978", nullptr);
  if (raw == nullptr)
    return Error{ErrorKind::kUsage,
                 fmt::format("--crs {}: PROJ does not know this coordinate system", crs)};
  // x = easting (or longitude), y = northing (or latitude), whatever the CRS's axis order.
  p.toEcef = proj_normalize_for_visualization(p.context, raw);
  proj_destroy(raw);
  if (p.toEcef == nullptr)
    return Error{ErrorKind::kUsage, fmt::format("--crs {}: cannot transform it to ECEF", crs)};
  // The frame's origin: the sample point, on the ellipsoid.
  PJ_COORD c = proj_trans(p.toEcef, PJ_FWD, proj_coord(sample.x, sample.y, sample.z, 0));
  if (!std::isfinite(c.xyz.x))
    return Error{ErrorKind::kBadInput,
                 fmt::format("--crs {}: the input point ({}, {}, {}) is outside it", crs, sample.x,
                             sample.y, sample.z)};
  const double x = c.xyz.x, y = c.xyz.y, z = c.xyz.z;
  // ECEF to geodetic by Bowring's iteration (converges to well under a millimetre here).
  const double lon = std::atan2(y, x), r = std::hypot(x, y);
  double lat = std::atan2(z, r * (1 - kEccentricity2)), height = 0;
  for (int i = 0; i < 6; ++i) {
    const double n = kSemiMajor / std::sqrt(1 - kEccentricity2 * std::sin(lat) * std::sin(lat));
    height = r / std::cos(lat) - n;
    lat = std::atan2(z, r * (1 - kEccentricity2 * n / (n + height)));
  }
  out.origin_ = {lon * 180 / std::numbers::pi, lat * 180 / std::numbers::pi, height};
  out.localToEcef_ = eastNorthUpToEcef(out.origin_);
  out.ecefToLocal_ = inverseRigid(out.localToEcef_);
  return out;
}

bool CrsToLocal::apply(Vec3d in, Vec3d& out) const {
  const PJ_COORD c = proj_trans(projection_->toEcef, PJ_FWD, proj_coord(in.x, in.y, in.z, 0));
  if (!std::isfinite(c.xyz.x) || !std::isfinite(c.xyz.y) || !std::isfinite(c.xyz.z)) return false;
  out = ecefToLocal_.transformPoint({c.xyz.x, c.xyz.y, c.xyz.z});
  return true;
}

}  // namespace lodforge
