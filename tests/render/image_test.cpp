#include "lodforge/render/image.h"

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "test_support.h"

namespace lodforge {
namespace {

Image solid(std::uint32_t w, std::uint32_t h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  Image image(w, h);
  for (std::size_t i = 0; i < image.pixelCount(); ++i) {
    image.rgba[4 * i] = r;
    image.rgba[4 * i + 1] = g;
    image.rgba[4 * i + 2] = b;
    image.rgba[4 * i + 3] = 255;
  }
  return image;
}

float deltaEOf(std::uint8_t r0, std::uint8_t g0, std::uint8_t b0, std::uint8_t r1, std::uint8_t g1,
               std::uint8_t b1) {
  const Image a = solid(1, 1, r0, g0, b0), b = solid(1, 1, r1, g1, b1);
  std::vector<float> e(1);
  deltaE76(a.rgba, b.rgba, e);
  return e[0];
}

TEST(DeltaE76, KnownColourPairs) {
  // Black (L 0) to white (L 100): only lightness differs.
  EXPECT_NEAR(deltaEOf(0, 0, 0, 255, 255, 255), 100.0, 0.01);
  // sRGB red is L 53.24, a 80.09, b 67.20 (D65): its distance to black is that vector's length.
  EXPECT_NEAR(deltaEOf(255, 0, 0, 0, 0, 0),
              std::sqrt(53.24 * 53.24 + 80.09 * 80.09 + 67.20 * 67.20), 0.1);
  // Mid grey 128 is L 53.59; 119 is L 50.03.
  EXPECT_NEAR(deltaEOf(128, 128, 128, 119, 119, 119), 53.59 - 50.03, 0.05);
  EXPECT_EQ(deltaEOf(10, 20, 30, 10, 20, 30), 0.0f);
}

TEST(DeltaE76, SymmetricAndTriangleInequality) {
  Random random(5);
  for (int i = 0; i < 2000; ++i) {
    std::uint8_t c[9];
    for (auto& x : c) x = static_cast<std::uint8_t>(random.below(256));
    const float ab = deltaEOf(c[0], c[1], c[2], c[3], c[4], c[5]);
    EXPECT_FLOAT_EQ(ab, deltaEOf(c[3], c[4], c[5], c[0], c[1], c[2]));
    EXPECT_LE(ab, deltaEOf(c[0], c[1], c[2], c[6], c[7], c[8]) +
                      deltaEOf(c[6], c[7], c[8], c[3], c[4], c[5]) + 1e-3f);
  }
}

TEST(CompareImages, SharesMeanAndPsnr) {
  Image a = solid(10, 10, 100, 100, 100), b = a;
  ImageDifference same = compareImages(a, b);
  EXPECT_EQ(same.pixelsAbove, 0u);
  EXPECT_EQ(same.meanDeltaE, 0.0);
  EXPECT_TRUE(std::isinf(same.psnr));
  // 25 of 100 pixels turn white: ΔE there is that of grey 100 to white.
  for (std::uint32_t y = 0; y < 5; ++y) {
    for (std::uint32_t x = 0; x < 5; ++x) {
      for (int c = 0; c < 3; ++c) b.rgba[4 * (y * 10 + x) + static_cast<std::size_t>(c)] = 255;
    }
  }
  const float e = deltaEOf(100, 100, 100, 255, 255, 255);
  std::vector<float> values;
  const ImageDifference d = compareImages(a, b, kJustNoticeableDeltaE, &values);
  EXPECT_EQ(d.pixels, 100u);
  EXPECT_EQ(d.pixelsAbove, 25u);
  EXPECT_DOUBLE_EQ(d.shareAbove, 0.25);
  EXPECT_NEAR(d.meanDeltaE, 0.25 * e, 1e-4);
  EXPECT_NEAR(d.maxDeltaE, e, 1e-4);
  // MSE = 0.25 * 155^2 over every channel.
  EXPECT_NEAR(d.psnr, 10 * std::log10(255.0 * 255.0 / (0.25 * 155.0 * 155.0)), 1e-9);
  ASSERT_EQ(values.size(), 100u);
  EXPECT_EQ(values[99], 0.0f);
  // The heat map is black where equal and bright where not.
  const Image heat = deltaEHeatMap(values, 10, 10);
  EXPECT_EQ(heat.rgba[4 * 99], 0);
  EXPECT_GT(heat.rgba[0] + heat.rgba[1] + heat.rgba[2], 200);
}

TEST(Png, RoundTripIsExact) {
  test::TempDir folder;
  Image image(37, 21);
  Random random(11);
  for (auto& byte : image.rgba) byte = static_cast<std::uint8_t>(random.below(256));
  const std::string path = folder.file("a.png");
  ASSERT_TRUE(writePng(path, image).ok());
  const auto back = readPng(path);
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->width, 37u);
  EXPECT_EQ(back->height, 21u);
  EXPECT_EQ(back->rgba, image.rgba);
}

TEST(Png, BadFilesAreBadInputNamingTheFile) {
  test::TempDir folder;
  const std::string text = folder.file("not.png");
  std::ofstream(text) << "hello";
  auto r = readPng(text);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(r.error().message.find("not.png"), std::string::npos);
  // A real signature followed by garbage.
  const std::string broken = folder.file("broken.png");
  std::ofstream(broken, std::ios::binary) << "\x89PNG\r\n\x1a\n garbage garbage";
  r = readPng(broken);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(r.error().message.find("broken.png"), std::string::npos);
  EXPECT_FALSE(readPng(folder.file("missing.png")).ok());
}

TEST(Png, ChunksBeyondTheEndAreRefusedWithTheirOffset) {
  test::TempDir folder;
  ASSERT_TRUE(writePng(folder.file("ok.png"), Image(3, 2)).ok());
  std::string bytes = test::readFile(folder.file("ok.png"));
  const auto span = [](const std::string& b) {
    return std::span(reinterpret_cast<const std::byte*>(b.data()), b.size());
  };
  ASSERT_TRUE(readPngFromMemory(span(bytes), "ok.png").ok());
  // The IHDR chunk (at byte 8) claims 2 GiB of data.
  std::string huge = bytes;
  huge[8] = '\x7f';
  auto r = readPngFromMemory(span(huge), "huge.png");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(r.error().message.find("chunk at byte 8"), std::string::npos) << r.error().message;
  // Cut inside the last chunk, and without IEND.
  for (std::size_t cut : {bytes.size() - 5, bytes.size() - 12}) {
    r = readPngFromMemory(span(bytes.substr(0, cut)), "cut.png");
    ASSERT_FALSE(r.ok()) << cut;
    EXPECT_EQ(r.error().kind, ErrorKind::kBadInput);
    EXPECT_EQ(r.error().message.rfind("cut.png: ", 0), 0u) << r.error().message;
  }
  // Bigger than the caller allows: refused before decoding.
  r = readPngFromMemory(span(bytes), "small.png", 5);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("3x2"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace lodforge
