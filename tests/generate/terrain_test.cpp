#include "lodforge/generate/terrain.h"

#include <gtest/gtest.h>

namespace lodforge {
namespace {

TEST(Terrain, HasHolesAwayFromTheEdgesAndAnOverhangingCliff) {
  const Terrain terrain(1, 1000, 667, 1.0);
  int holes = 0, samples = 0;
  for (double v = 0; v < 667; v += 2) {
    for (double u = 0; u < 1000; u += 2) {
      ++samples;
      if (terrain.inHole(u, v)) {
        ++holes;
        EXPECT_GT(u, 1000 / 6.0 * 0.9);
        EXPECT_LT(u, 1000 - 1000 / 6.0 * 0.9);
      }
    }
  }
  EXPECT_GT(holes, 0);
  EXPECT_LT(holes, samples / 10);
  // Along a row across the cliff, x goes backwards somewhere while z keeps rising: an overhang.
  bool overhang = false;
  for (double v = 0; v < 600 && !overhang; v += 50) {
    Vec3d previous = terrain.position(400, v);
    for (double u = 400.5; u < 800; u += 0.5) {
      const Vec3d p = terrain.position(u, v);
      if (p.x < previous.x && p.z > previous.z) overhang = true;
      previous = p;
    }
  }
  EXPECT_TRUE(overhang);
}

TEST(Terrain, NormalsAreUnitAndSomeFaceDownUnderTheOverhang) {
  const Terrain terrain(3, 1000, 667, 1.0);
  bool down = false;
  for (double v = 10; v < 660; v += 25) {
    for (double u = 0; u < 1000; u += 0.5) {
      const Vec3d n = terrain.normal(u, v);
      ASSERT_NEAR(length(n), 1.0, 1e-9);
      down = down || n.z < -0.2;
    }
  }
  EXPECT_TRUE(down);
}

TEST(Terrain, IsDeterministicPerSeed) {
  const Terrain a(5, 100, 100, 0.1), b(5, 100, 100, 0.1), c(6, 100, 100, 0.1);
  EXPECT_EQ(a.position(12.5, 40.25), b.position(12.5, 40.25));
  EXPECT_NE(a.position(12.5, 40.25), c.position(12.5, 40.25));
}

}  // namespace
}  // namespace lodforge
