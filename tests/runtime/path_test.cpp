#include "lodforge/runtime/path.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_support.h"

namespace lodforge {
namespace {

const Aabbd kBounds{{-2, -1, 0}, {6, 1, 1.5}};

TEST(Path, OrbitCirclesTheModelAndSeesAllOfIt) {
  const auto cameras = orbitPath(kBounds, {.frames = 16, .width = 640, .height = 480});
  ASSERT_EQ(cameras.size(), 16u);
  const double radius = length(cameras[0].position - kBounds.center());
  for (const Camera& c : cameras) {
    EXPECT_NEAR(length(c.position - kBounds.center()), radius, 1e-9);
    EXPECT_GT(c.position.z, kBounds.center().z);  // looks down a little
    EXPECT_NEAR(dot(c.forward, normalizeOr(kBounds.center() - c.position, Vec3d{})), 1, 1e-12);
    // The whole box is in front, inside the clip range, and on screen.
    const ViewProjection v(c);
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3d p = kBounds.corner(corner);
      const Vec3d d = p - c.position;
      const double z = dot(d, c.forward);
      EXPECT_GT(z, c.nearPlane);
      EXPECT_LT(z, c.farPlane);
      EXPECT_LT(std::abs(dot(d, c.right())) / z, v.tanX);
      EXPECT_LT(std::abs(dot(d, c.up)) / z, v.tanY);
    }
  }
  // Consecutive frames are distinct and the loop does not repeat its first frame.
  EXPECT_GT(length(cameras.back().position - cameras.front().position), 0.1);
}

// The framed orbit keeps every corner of the box on screen and fills the frame: in each frame
// the farthest corner from the middle is at 90 % of the half-width or half-height, where the
// fixed-radius orbit leaves the box smaller (here 82 % at the least).
TEST(Path, FramedOrbitFillsTheFrameFromEverySide) {
  const PathOptions options{.frames = 12, .width = 640, .height = 480};
  const auto framed = framedOrbitPath(kBounds, {}, options);
  const auto orbit = orbitPath(kBounds, options);
  ASSERT_EQ(framed.size(), 12u);
  double orbitFill = 1;
  for (std::size_t f = 0; f < framed.size(); ++f) {
    const auto fill = [&](const Camera& c) {
      const ViewProjection v(c);
      double most = 0;
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3d p = kBounds.corner(corner);
        const Vec3d d = p - c.position;
        const double z = dot(d, c.forward);
        EXPECT_GT(z, c.nearPlane);
        most = std::max(
            {most, std::abs(dot(d, c.right())) / z / v.tanX, std::abs(dot(d, c.up)) / z / v.tanY});
      }
      return most;
    };
    EXPECT_NEAR(fill(framed[f]), 0.9, 1e-6) << "frame " << f;
    // The same directions as the orbit.
    EXPECT_NEAR(dot(framed[f].forward, orbit[f].forward), 1, 1e-9) << "frame " << f;
    orbitFill = std::min(orbitFill, fill(orbit[f]));
  }
  EXPECT_LT(orbitFill, 0.9) << "the fixed orbit leaves the box smaller in some frame";
}

TEST(Path, FlyThroughRunsAlongTheLongestHorizontalAxis) {
  const auto cameras = flyThroughPath(kBounds, {.frames = 30});
  ASSERT_EQ(cameras.size(), 30u);
  EXPECT_LT(cameras.front().position.x, kBounds.min.x);
  EXPECT_GT(cameras.back().position.x, kBounds.max.x);
  for (std::size_t i = 1; i < cameras.size(); ++i) {
    EXPECT_GT(cameras[i].position.x, cameras[i - 1].position.x);
    EXPECT_GT(cameras[i].forward.x, 0.9);  // looking ahead, swaying a little
    EXPECT_NEAR(cameras[i].position.z, kBounds.center().z, 1e-12);
  }
}

TEST(Path, JsonRoundTripKeepsEveryCamera) {
  test::TempDir dir;
  const Vec3d origin{1000, 2000, 30};
  auto cameras = orbitPath(kBounds, {.frames = 5, .width = 333, .height = 222, .fovYDegrees = 47});
  cameras[2].nearPlane = 0.125;
  ASSERT_TRUE(writeCameraPath(dir.file("p.json"), cameras, origin).ok());
  EXPECT_EQ(test::listFolder(dir.path()), std::vector<std::string>{"p.json"});
  Result<std::vector<Camera>> back = readCameraPath(dir.file("p.json"), origin, kBounds);
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->size(), cameras.size());
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const Camera &a = cameras[i], &b = (*back)[i];
    EXPECT_NEAR(length(a.position - b.position), 0, 1e-9);
    EXPECT_NEAR(length(a.forward - b.forward), 0, 1e-9);
    EXPECT_NEAR(length(a.up - b.up), 0, 1e-9);
    EXPECT_NEAR(a.fovY, b.fovY, 1e-12);
    EXPECT_DOUBLE_EQ(a.nearPlane, b.nearPlane);
    EXPECT_DOUBLE_EQ(a.farPlane, b.farPlane);
    EXPECT_EQ(b.width, 333u);
    EXPECT_EQ(b.height, 222u);
  }
  // Positions in the file are model coordinates: the origin is added back.
  const auto json = nlohmann::json::parse(test::readFile(dir.file("p.json")));
  EXPECT_NEAR(json["frames"][0]["position"][0].get<double>(), cameras[0].position.x + 1000, 1e-9);
}

TEST(Path, MinimalFramesGetDefaultsAndFittedClipPlanes) {
  test::TempDir dir;
  test::writeFile(dir.file("p.json"),
                  R"({"frames": [{"position": [10, 0, 1], "target": [0, 0, 1]}]})");
  Result<std::vector<Camera>> p = readCameraPath(dir.file("p.json"), {}, kBounds);
  ASSERT_TRUE(p.ok()) << p.error().message;
  ASSERT_EQ(p->size(), 1u);
  EXPECT_EQ((*p)[0].width, 1280u);
  EXPECT_NEAR((*p)[0].fovY, 60.0 * 3.14159265358979323846 / 180.0, 1e-12);
  EXPECT_LT((*p)[0].nearPlane, 1e-3);
  EXPECT_GT((*p)[0].farPlane, 20.0);
}

TEST(Path, MalformedPathsNameTheFileAndWhere) {
  test::TempDir dir;
  const std::pair<const char*, const char*> cases[] = {
      {R"({"frames": [ {"position": [1, 2, 3], "target": )",
       "byte 48: the camera path is not valid JSON"},
      {R"([1, 2])", "a JSON object"},
      {R"({"frames": []})", "non-empty array"},
      {R"({"frames": [{"position": [1, 2, 3], "target": [0, 0, 0]}, {"position": [1, 2], "target": [0, 0, 0]}]})",
       "frame 1:"},
      {R"({"frames": [{"position": [1, 2, 3], "target": [1, 2, 3]}]})",
       "frame 0: \"target\" equals"},
      {R"({"frames": [{"position": [1, 2, 3], "target": [0, "x", 0]}]})", "frame 0:"},
      {R"({"frames": [{"position": [1, 2, 3], "target": [0, 0, 0], "fovY": 200}]})", "fovY"},
      {R"({"frames": [{"position": [1, 2, 3], "target": [0, 0, 0], "near": 5, "far": 1}]})",
       "\"far\" must exceed"},
      {R"({"frames": [{"position": [1, 2, 3], "target": [0, 0, 0], "up": [0, 0, 0]}]})", "\"up\""},
      {R"({"viewport": [0, 100], "frames": [{"position": [1, 2, 3], "target": [0, 0, 0]}]})",
       "viewport"},
      {R"({"viewport": [-5, 100], "frames": [{"position": [1, 2, 3], "target": [0, 0, 0]}]})",
       "viewport"},
  };
  for (const auto& [text, expected] : cases) {
    test::writeFile(dir.file("bad.json"), text);
    Result<std::vector<Camera>> p = readCameraPath(dir.file("bad.json"), {}, kBounds);
    ASSERT_FALSE(p.ok()) << text;
    EXPECT_EQ(p.error().kind, ErrorKind::kBadInput) << text;
    EXPECT_NE(p.error().message.find(dir.file("bad.json")), std::string::npos) << p.error().message;
    EXPECT_NE(p.error().message.find(expected), std::string::npos) << p.error().message;
  }
  Result<std::vector<Camera>> missing = readCameraPath(dir.file("none.json"), {}, kBounds);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("none.json"), std::string::npos);
}

}  // namespace
}  // namespace lodforge
