#include "lodforge/runtime/gaze.h"

#include <array>
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "lodforge/points/build.h"
#include "test_support.h"

namespace lodforge {
namespace {

// A 200 m x 100 m wavy sheet of points, built into a package of ~12 blocks.
class GazeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Random random(5);
    {
      std::ofstream out(dir_.file("sheet.xyz"));
      out.precision(10);
      for (int i = 0; i < kPoints; ++i) {
        const double x = random.uniform(0, 200), y = random.uniform(0, 100);
        out << x << ' ' << y << ' ' << 2 * std::sin(x / 10) << '\n';
      }
    }
    PointsBuildOptions options;
    options.blockSize = 2'000;
    ASSERT_TRUE(buildPointCloud(dir_.file("sheet.xyz"), dir_.file("s.lfc"), options).ok());
    Result<CloudFile> cloud = CloudFile::open(dir_.file("s.lfc"));
    ASSERT_TRUE(cloud.ok());
    cloud_.emplace(std::move(*cloud));
  }
  // From above the sheet's centre, seeing all of it.
  static Camera overview() {
    return Camera::lookAt({100, -60, 160}, {100, 50, 0}, {0, 0, 1}, 60, 800, 600);
  }
  static constexpr int kPoints = 24'000;
  test::TempDir dir_;
  std::optional<CloudFile> cloud_;
};

TEST(Fovea, FullResolutionInsideThenDegrading) {
  FoveaOptions fovea;
  fovea.radius = 100;
  fovea.fovealSplat = 2;
  fovea.falloff = 3;
  EXPECT_DOUBLE_EQ(allowedSplatPixels(fovea, 0), 2);
  EXPECT_DOUBLE_EQ(allowedSplatPixels(fovea, 100), 2);
  EXPECT_DOUBLE_EQ(allowedSplatPixels(fovea, 200), 8);
  double last = 0;
  for (double d = 0; d < 1000; d += 7) {
    EXPECT_GE(allowedSplatPixels(fovea, d), last);
    last = allowedSplatPixels(fovea, d);
  }
}

TEST_F(GazeTest, WithoutResidentBlocksPartTwoIsDrawnAndBlocksAreWanted) {
  BlockPager pager(*cloud_, 4, 2);
  PointSelection selection;
  selectPoints(*cloud_, pager, overview(), FoveaOptions{}, 1, selection);
  EXPECT_EQ(selection.visibleBlocks, cloud_->blocks().size());
  EXPECT_EQ(selection.size(), cloud_->resident().size());
  EXPECT_EQ(selection.inputPoints, static_cast<std::uint64_t>(kPoints));
  EXPECT_EQ(selection.refinedBlocks, 0u);
  EXPECT_FALSE(selection.wanted.empty());
}

TEST_F(GazeTest, RefinesInsideTheFoveaToTheAllowedSplatSize) {
  // With every block resident, every drawn splat is a leaf or within the allowed size at its
  // distance from the gaze; every input point is drawn exactly once (counts add up).
  const Camera camera = overview();
  FoveaOptions fovea;
  fovea.gazeX = 250;
  fovea.gazeY = 300;
  fovea.radius = 120;
  BlockPager pager(*cloud_, cloud_->blocks().size(), cloud_->blocks().size());
  PointSelection selection;
  for (std::uint64_t frame = 1; frame <= 3; ++frame) {
    selectPoints(*cloud_, pager, camera, fovea, frame, selection);
    ASSERT_TRUE(pager.update(selection.wanted, frame).ok());
  }
  EXPECT_TRUE(selection.wanted.empty());
  EXPECT_EQ(selection.inputPoints, static_cast<std::uint64_t>(kPoints));
  EXPECT_GT(selection.size(), cloud_->resident().size());
  // Leaves may be bigger (nothing finer exists); the rest obey the degradation function.
  const ViewProjection view(camera);
  const auto screen = [&](std::size_t i) {
    const Vec3d d = selection.origin + toDouble(selection.positions[i]) - view.origin;
    const double z = dot(d, view.forward);
    return std::array<double, 3>{view.halfWidth * (1 + dot(d, view.right) / z / view.tanX),
                                 view.halfHeight * (1 - dot(d, view.up) / z / view.tanY),
                                 2 * selection.radii[i] * camera.pixelScale() / z};
  };
  for (std::size_t i = 0; i < selection.size(); ++i) {
    const auto [sx, sy, diameter] = screen(i);
    const double fromGaze = std::max(0.0, std::hypot(sx - 250, sy - 300) - diameter / 2);
    if (diameter > allowedSplatPixels(fovea, fromGaze) * 1.0001) {
      EXPECT_LT(selection.radii[i], 2.0f) << "a coarse splat too big at " << fromGaze << " px";
    }
  }
  // More splats around the gaze than around the mirror point, and the other way round once
  // the gaze moves there.
  const auto around = [&](double x, double y) {
    std::size_t count = 0;
    for (std::size_t i = 0; i < selection.size(); ++i) {
      const auto [sx, sy, diameter] = screen(i);
      count += std::hypot(sx - x, sy - y) < 100;
    }
    return count;
  };
  EXPECT_GT(around(250, 300), 2 * around(550, 300));
  fovea.gazeX = 550;
  for (std::uint64_t frame = 4; frame <= 6; ++frame) {
    selectPoints(*cloud_, pager, camera, fovea, frame, selection);
    ASSERT_TRUE(pager.update(selection.wanted, frame).ok());
  }
  EXPECT_GT(around(550, 300), 2 * around(250, 300));
  EXPECT_EQ(selection.inputPoints, static_cast<std::uint64_t>(kPoints));
}

TEST_F(GazeTest, PagerKeepsAFixedNumberOfBlocksNearestTheGaze) {
  const Camera camera = overview();
  FoveaOptions fovea;
  fovea.radius = 60;
  BlockPager pager(*cloud_, 3, 1);
  PointSelection selection;
  std::uint64_t frame = 0;
  for (double gazeX : {100.0, 700.0}) {
    fovea.gazeX = gazeX;
    for (int i = 0; i < 8; ++i) {
      ++frame;
      selectPoints(*cloud_, pager, camera, fovea, frame, selection);
      std::vector<BlockPager::Request> wanted = selection.wanted;
      Result<std::size_t> loaded = pager.update(wanted, frame);
      ASSERT_TRUE(loaded.ok());
      EXPECT_LE(*loaded, 1u);  // loads per frame
      EXPECT_LE(pager.residentCount(), 3u);
      if (!wanted.empty() && *loaded == 1) {
        // What was loaded is the wanted block nearest the gaze.
        const auto nearest = std::min_element(wanted.begin(), wanted.end(), [](auto& a, auto& b) {
          return a.gazeDistance < b.gazeDistance;
        });
        EXPECT_TRUE(pager.info()[nearest->block].resident);
      }
    }
    // After a few frames the resident blocks are those the gaze ray passes nearest.
    for (std::size_t b = 0; b < pager.info().size(); ++b) {
      if (!pager.info()[b].resident) continue;
      std::size_t nearer = 0;
      for (const auto& other : pager.info())
        nearer += other.gazeDistance < pager.info()[b].gazeDistance;
      EXPECT_LT(nearer, 6u) << "block " << b;
    }
  }
  EXPECT_GT(pager.loads(), 3u);  // the second gaze paged in other blocks
  std::uint64_t calls = 0;
  for (const auto& s : pager.info()) calls += s.calls;
  EXPECT_GT(calls, 0u);
}

}  // namespace
}  // namespace lodforge
