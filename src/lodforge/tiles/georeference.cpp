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

// A 2D projected CRS says nothing of heights, and PROJ takes them as metres; a LAS file in a
// CRS in feet stores them in feet, as its x and y. Heights are then taken in the CRS's linear
// unit (0.3048 for a foot); a CRS with a vertical part (compound, 3D) says its own.
// `source` is the CRS as PROJ reads it (null: it does not).
double heightScaleOf(PJ_CONTEXT* context, PJ* source) {
  if (source == nullptr) return 1;
  double factor = 1;
  if (proj_get_type(source) == PJ_TYPE_PROJECTED_CRS) {
    if (PJ* cs = proj_crs_get_coordinate_system(context, source)) {
      if (proj_cs_get_axis_count(context, cs) == 2 &&
          !proj_cs_get_axis_info(context, cs, 0, nullptr, nullptr, nullptr, &factor, nullptr,
                                 nullptr, nullptr))
        factor = 1;
      proj_destroy(cs);
    }
  }
  return factor > 0 && std::isfinite(factor) ? factor : 1;
}

// What to do about a CRS that cannot be the data's.
constexpr const char* kPlacementFix =
    "give the data's coordinate system with --crs EPSG:N, or place it with --origin "
    "LON,LAT,HEIGHT";

// The CRS's name as PROJ gives it ("NAD83 / UTM zone 10N"), else the text as given, shortened
// (a WKT runs to kilobytes).
std::string crsName(PJ* source, const std::string& crs) {
  std::string name;
  if (source != nullptr)
    if (const char* n = proj_get_name(source)) name = n;
  if (name.empty()) name = crs.size() > 60 ? crs.substr(0, 57) + "..." : crs;
  return name;
}

// The sample placed by the CRS lies near the Earth's surface, and not far outside the CRS's
// area of use where PROJ knows it (a UTM zone may be used a little beyond its 6 degrees).
Status checkPlausible(PJ_CONTEXT* context, PJ* source, const std::string& named, Vec3d sample,
                      const Geodetic& at) {
  constexpr double kDeepest = -20'000, kHighest = 100'000, kAreaMargin = 5;  // metres, degrees
  if (at.height < kDeepest || at.height > kHighest)
    return Error{
        ErrorKind::kBadInput,
        fmt::format("{} puts the input point ({}, {}, {}) {:.0f} km {} the Earth's "
                    "surface (at {:.4f}, {:.4f}): it cannot be the data's; {}",
                    named, sample.x, sample.y, sample.z, std::abs(at.height) / 1000,
                    at.height < 0 ? "under" : "over", at.longitude, at.latitude, kPlacementFix)};
  double west = 0, south = 0, east = 0, north = 0;
  const bool known = source != nullptr &&
                     proj_get_area_of_use(context, source, &west, &south, &east, &north, nullptr) &&
                     west > -1000;
  if (!known) return {};
  const bool wraps = west > east;  // an area across the antimeridian
  const double lon = at.longitude;
  const bool inLongitude = wraps ? lon >= west - kAreaMargin || lon <= east + kAreaMargin
                                 : lon >= west - kAreaMargin && lon <= east + kAreaMargin;
  if (inLongitude && at.latitude >= south - kAreaMargin && at.latitude <= north + kAreaMargin)
    return {};
  return Error{ErrorKind::kBadInput,
               fmt::format("{} puts the input point ({}, {}, {}) at {:.4f}, {:.4f}, far outside "
                           "the area it is for ({:g} to {:g} east, {:g} to {:g} north): it "
                           "cannot be the data's; {}",
                           named, sample.x, sample.y, sample.z, at.longitude, at.latitude, west,
                           east, south, north, kPlacementFix)};
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
  PJ* source = nullptr;  // the input's CRS as PROJ reads it, for its name, unit and area
  PJ* toEcef = nullptr;
  double heightScale = 1;  // metres per input height unit (heightScaleOf)
  ~Projection() {
    if (toEcef != nullptr) proj_destroy(toEcef);
    if (source != nullptr) proj_destroy(source);
    if (context != nullptr) proj_context_destroy(context);
  }
};

CrsToLocal::CrsToLocal(CrsToLocal&&) noexcept = default;
CrsToLocal& CrsToLocal::operator=(CrsToLocal&&) noexcept = default;
CrsToLocal::~CrsToLocal() = default;

Result<CrsToLocal> CrsToLocal::create(const std::string& crs, Vec3d sample,
                                      const std::string& from) {
  CrsToLocal out;
  out.projection_ = std::make_unique<Projection>();
  Projection& p = *out.projection_;
  p.context = proj_context_create();
  proj_log_level(p.context, PJ_LOG_NONE);
  p.source = proj_create(p.context, crs.c_str());
  const std::string named = fmt::format("{} ({})", from, crsName(p.source, crs));
  PJ* raw = proj_create_crs_to_crs(p.context, crs.c_str(), "EPSG:4978", nullptr);
  if (raw == nullptr)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: PROJ does not know this coordinate system", named)};
  // x = easting (or longitude), y = northing (or latitude), whatever the CRS's axis order.
  p.toEcef = proj_normalize_for_visualization(p.context, raw);
  proj_destroy(raw);
  if (p.toEcef == nullptr)
    return Error{ErrorKind::kUsage, fmt::format("{}: cannot transform it to ECEF", named)};
  p.heightScale = heightScaleOf(p.context, p.source);
  // The frame's origin: the sample point, on the ellipsoid.
  PJ_COORD c =
      proj_trans(p.toEcef, PJ_FWD, proj_coord(sample.x, sample.y, sample.z * p.heightScale, 0));
  if (!std::isfinite(c.xyz.x))
    return Error{ErrorKind::kBadInput,
                 fmt::format("{}: the input point ({}, {}, {}) is outside it; {}", named, sample.x,
                             sample.y, sample.z, kPlacementFix)};
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
  LODFORGE_TRY(checkPlausible(p.context, p.source, named, sample, out.origin_));
  out.localToEcef_ = eastNorthUpToEcef(out.origin_);
  out.ecefToLocal_ = inverseRigid(out.localToEcef_);
  return out;
}

bool CrsToLocal::apply(Vec3d in, Vec3d& out) const {
  const PJ_COORD c = proj_trans(projection_->toEcef, PJ_FWD,
                                proj_coord(in.x, in.y, in.z * projection_->heightScale, 0));
  if (!std::isfinite(c.xyz.x) || !std::isfinite(c.xyz.y) || !std::isfinite(c.xyz.z)) return false;
  out = ecefToLocal_.transformPoint({c.xyz.x, c.xyz.y, c.xyz.z});
  return true;
}

}  // namespace lodforge
