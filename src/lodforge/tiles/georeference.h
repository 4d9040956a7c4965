// Georeferencing for 3D Tiles: tile contents live in a local east-north-up frame (metres) and the
// root tile's transform places that frame on the WGS84 ellipsoid (ECEF, EPSG:4978), as CesiumJS
// expects. Input in a projected or geographic CRS goes through PROJ point by point, in double
// precision end to end.
#pragma once

#include <memory>
#include <string>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"

namespace lodforge {

struct Geodetic {
  double longitude = 0, latitude = 0, height = 0;  // degrees, degrees, metres
};

// WGS84 geodetic to ECEF (metres).
Vec3d geodeticToEcef(const Geodetic& g);
// The east-north-up frame at `g`: columns east, north, up, origin (ECEF).
Mat4d eastNorthUpToEcef(const Geodetic& g);
// "LON,LAT,HEIGHT" (degrees, metres); a usage error names the option.
Result<Geodetic> parseOrigin(const std::string& text);

// Input coordinates in `crs` (e.g. "EPSG:32633") to a local east-north-up frame around a point.
class CrsToLocal {
 public:
  // `sample` is any input point (e.g. the first vertex): the frame's origin is that point on
  // the ellipsoid, so tile coordinates stay small. A CRS that puts the sample far from the
  // Earth's surface (more than 20 km under it or 100 km over it), or far outside the area PROJ
  // says the CRS is for, cannot be the data's: bad input. `from` says where the CRS came from
  // in messages ("--crs", "the CRS in scan.laz").
  static Result<CrsToLocal> create(const std::string& crs, Vec3d sample,
                                   const std::string& from = "--crs");
  CrsToLocal(CrsToLocal&&) noexcept;
  CrsToLocal& operator=(CrsToLocal&&) noexcept;
  ~CrsToLocal();

  // Input point to local ENU metres; false if PROJ cannot transform it. Heights in a 2D
  // projected CRS are in its linear unit (feet for a CRS in feet), as LAS stores them.
  bool apply(Vec3d in, Vec3d& out) const;
  const Mat4d& localToEcef() const { return localToEcef_; }
  const Geodetic& origin() const { return origin_; }

 private:
  struct Projection;
  CrsToLocal() = default;
  std::unique_ptr<Projection> projection_;
  Mat4d localToEcef_, ecefToLocal_;
  Geodetic origin_;
};

}  // namespace lodforge
