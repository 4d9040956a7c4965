#include "lodforge/tiles/georeference.h"

#include <cmath>

#include <gtest/gtest.h>

namespace lodforge {
namespace {

TEST(Georeference, EcefOfKnownPlaces) {
  const Vec3d equator = geodeticToEcef({0, 0, 0});
  EXPECT_NEAR(equator.x, 6378137.0, 1e-6);
  EXPECT_NEAR(equator.y, 0, 1e-6);
  const Vec3d pole = geodeticToEcef({0, 90, 0});
  EXPECT_NEAR(pole.z, 6356752.314245, 1e-5);  // WGS84 b
  const Vec3d up = geodeticToEcef({90, 0, 100});
  EXPECT_NEAR(up.y, 6378237.0, 1e-6);
}

TEST(Georeference, EastNorthUpIsARigidFrameOnTheEllipsoid) {
  const Geodetic zurich{8.5417, 47.3769, 408};
  const Mat4d m = eastNorthUpToEcef(zurich);
  const Vec3d origin = m.transformPoint({0, 0, 0});
  const Vec3d expected = geodeticToEcef(zurich);
  EXPECT_NEAR(length(origin - expected), 0, 1e-6);
  // 100 m up is 100 m higher; 100 m east keeps the height (to the curvature: 0.8 mm).
  EXPECT_NEAR(length(m.transformPoint({0, 0, 100}) - geodeticToEcef({8.5417, 47.3769, 508})), 0,
              1e-6);
  const Vec3d east = m.transformVector({1, 0, 0}), north = m.transformVector({0, 1, 0}),
              upward = m.transformVector({0, 0, 1});
  EXPECT_NEAR(dot(east, north), 0, 1e-12);
  EXPECT_NEAR(dot(east, upward), 0, 1e-12);
  EXPECT_NEAR(length(east), 1, 1e-12);
  EXPECT_NEAR(length(cross(east, north) - upward), 0, 1e-12);  // right-handed
  EXPECT_GT(dot(north, {0, 0, 1}), 0);                         // north points to the pole
}

TEST(Georeference, OriginParsing) {
  Result<Geodetic> g = parseOrigin("8.5417,47.3769,408");
  ASSERT_TRUE(g.ok());
  EXPECT_DOUBLE_EQ(g->latitude, 47.3769);
  for (const char* bad : {"8.5,47", "8.5;47;3", "200,10,0", "1,2,3x", "a,b,c"}) {
    Result<Geodetic> r = parseOrigin(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.error().kind, ErrorKind::kUsage);
  }
}

TEST(Georeference, UtmThroughProjLandsWhereItShould) {
  // UTM 33N, easting 500,000 on the equator: 15 degrees east, height 0.
  Result<CrsToLocal> utm = CrsToLocal::create("EPSG:32633", {500000, 0, 0});
  ASSERT_TRUE(utm.ok()) << utm.error().message;
  EXPECT_NEAR(utm->origin().longitude, 15, 1e-9);
  EXPECT_NEAR(utm->origin().latitude, 0, 1e-9);
  EXPECT_NEAR(utm->origin().height, 0, 1e-6);
  Vec3d local;
  ASSERT_TRUE(utm->apply({500000, 0, 0}, local));
  EXPECT_NEAR(length(local), 0, 1e-6);
  // 1 km north on the grid is ~1 km north locally (UTM scale 0.9996 on the central meridian).
  ASSERT_TRUE(utm->apply({500000, 1000, 0}, local));
  EXPECT_NEAR(local.x, 0, 1e-6);
  EXPECT_NEAR(local.y, 1000 / 0.9996, 0.01);
  EXPECT_LT(std::abs(local.z), 0.2);  // the Earth curves 8 cm in 1 km
  const Vec3d ecef = utm->localToEcef().transformPoint({0, 0, 0});
  EXPECT_NEAR(length(ecef - geodeticToEcef({15, 0, 0})), 0, 1e-6);
  // Unknown systems are a usage error.
  Result<CrsToLocal> bad = CrsToLocal::create("EPSG:999999", {0, 0, 0});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().kind, ErrorKind::kUsage);
}

}  // namespace
}  // namespace lodforge
