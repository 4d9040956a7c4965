#include "lodforge/tiles/texture_pyramid.h"

#include <gtest/gtest.h>

#include "lodforge/io/image/image_codec.h"
#include "test_support.h"

namespace lodforge {
namespace {

Image gradient(std::uint32_t width, std::uint32_t height) {
  Image image(width, height);
  for (std::uint32_t y = 0; y < height; ++y)
    for (std::uint32_t x = 0; x < width; ++x) {
      std::uint8_t* p = &image.rgba[4 * (std::size_t{y} * width + x)];
      p[0] = static_cast<std::uint8_t>(x);
      p[1] = static_cast<std::uint8_t>(y);
      p[2] = static_cast<std::uint8_t>((x * 7 + y * 3) % 256);
      p[3] = 255;
    }
  return image;
}

ImageSource embeddedPng(const Image& image) {
  Result<std::vector<std::byte>> png = encodeImage(image, {.format = ImageFormat::kPng});
  EXPECT_TRUE(png.ok());
  ImageSource source{.name = "gradient", .bytes = png.ok() ? *png : std::vector<std::byte>{}};
  EXPECT_TRUE(probeImage(source).ok());
  return source;
}

TEST(TexturePyramid, WrapModesRepeatMirrorAndClamp) {
  EXPECT_EQ(wrapTexel(-1, 4, TextureWrap::kRepeat), 3);
  EXPECT_EQ(wrapTexel(9, 4, TextureWrap::kRepeat), 1);
  EXPECT_EQ(wrapTexel(-1, 4, TextureWrap::kMirror), 0);
  EXPECT_EQ(wrapTexel(4, 4, TextureWrap::kMirror), 3);
  EXPECT_EQ(wrapTexel(9, 4, TextureWrap::kMirror), 1);  // 0 1 2 3 3 2 1 0 | 0 1
  EXPECT_EQ(wrapTexel(-5, 4, TextureWrap::kClamp), 0);
  EXPECT_EQ(wrapTexel(17, 4, TextureWrap::kClamp), 3);
  for (std::int64_t x = -20; x < 20; ++x)
    for (TextureWrap w : {TextureWrap::kRepeat, TextureWrap::kMirror, TextureWrap::kClamp}) {
      const std::int64_t t = wrapTexel(x, 5, w);
      EXPECT_GE(t, 0);
      EXPECT_LT(t, 5);
    }
}

TEST(TexturePyramid, HalvingAveragesInLinearLight) {
  Image image(2, 2);
  // Black and white: the mean in linear light is sRGB 188, not 128.
  const std::uint8_t values[4] = {0, 255, 255, 0};
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t c = 0; c < 3; ++c) image.rgba[4 * i + c] = values[i];
  for (std::size_t i = 0; i < 4; ++i) image.rgba[4 * i + 3] = 255;
  const Image half = halveImage(image);
  ASSERT_EQ(half.width, 1u);
  EXPECT_NEAR(half.rgba[0], 188, 1);
  EXPECT_EQ(half.rgba[3], 255);
  // Odd sizes round down, never below one texel.
  const Image odd = halveImage(gradient(5, 1));
  EXPECT_EQ(odd.width, 2u);
  EXPECT_EQ(odd.height, 1u);
}

TEST(TexturePyramid, RegionsReadBackTexelForTexelWithWraps) {
  test::TempDir dir;
  const Image image = gradient(150, 70);  // blocks of 64: partial ones at the right and bottom
  const ImageSource source = embeddedPng(image);
  Result<TexturePyramid> pyramid =
      TexturePyramid::build(std::span(&source, 1), dir.path().string(), /*cacheBytes=*/1);
  ASSERT_TRUE(pyramid.ok()) << pyramid.error().message;
  ASSERT_EQ(pyramid->levels(0), 8u);  // 150x70 75x35 37x17 18x8 9x4 4x2 2x1 1x1
  EXPECT_EQ(pyramid->width(0, 1), 75u);
  EXPECT_EQ(pyramid->height(0, 7), 1u);
  // A region across block borders and past the image's corner, repeated.
  const std::int64_t x0 = 120, y0 = 50;
  const std::uint32_t w = 50, h = 40;
  std::vector<std::uint8_t> out(std::size_t{w} * h * 4);
  ASSERT_TRUE(
      pyramid->read(0, 0, x0, y0, w, h, TextureWrap::kRepeat, TextureWrap::kMirror, out.data())
          .ok());
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) {
      const auto sx = static_cast<std::size_t>(wrapTexel(x0 + x, 150, TextureWrap::kRepeat));
      const auto sy = static_cast<std::size_t>(wrapTexel(y0 + y, 70, TextureWrap::kMirror));
      ASSERT_EQ(
          0, std::memcmp(&out[4 * (std::size_t{y} * w + x)], &image.rgba[4 * (sy * 150 + sx)], 4))
          << x << "," << y;
    }
  // A coarser level reads what halving made.
  const Image level1 = halveImage(image);
  std::vector<std::uint8_t> row(4 * 75);
  ASSERT_TRUE(
      pyramid->read(0, 1, 0, 20, 75, 1, TextureWrap::kClamp, TextureWrap::kClamp, row.data()).ok());
  EXPECT_EQ(0, std::memcmp(row.data(), &level1.rgba[4 * 20 * 75], row.size()));
}

TEST(TexturePyramid, AnImageThatCannotBeDecodedIsRefusedByName) {
  test::TempDir dir;
  ImageSource broken{.name = "broken.png", .path = dir.file("broken.png")};
  test::writeFile(broken.path, "\x89PNG\r\n\x1A\nnot really");
  Result<TexturePyramid> pyramid =
      TexturePyramid::build(std::span(&broken, 1), dir.path().string(), 1 << 20);
  ASSERT_FALSE(pyramid.ok());
  EXPECT_EQ(pyramid.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(pyramid.error().message.find("broken.png"), std::string::npos);
}

}  // namespace
}  // namespace lodforge
