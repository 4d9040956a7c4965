#include <gtest/gtest.h>

#include <cstdlib>
#include <tuple>

#include "lodforge/io/image/image_codec.h"
#include "test_support.h"
#include "texture_support.h"

namespace lodforge {
namespace {

// A photo-like pattern: smooth gradients plus a checker, with alpha when asked.
Image pattern(std::uint32_t width, std::uint32_t height, bool alpha = false) {
  Image image(width, height);
  for (std::uint32_t y = 0; y < height; ++y) {
    for (std::uint32_t x = 0; x < width; ++x) {
      std::uint8_t* p = image.rgba.data() + 4 * (std::size_t{y} * width + x);
      p[0] = static_cast<std::uint8_t>(x * 255 / width);
      p[1] = static_cast<std::uint8_t>(y * 255 / height);
      p[2] = ((x / 8 + y / 8) % 2) ? 200 : 60;
      p[3] = alpha ? static_cast<std::uint8_t>((x + y) % 256) : 255;
    }
  }
  return image;
}

double meanError(const Image& a, const Image& b) {
  EXPECT_EQ(a.rgba.size(), b.rgba.size());
  double sum = 0;
  for (std::size_t i = 0; i < a.rgba.size() && i < b.rgba.size(); ++i)
    sum += std::abs(int(a.rgba[i]) - int(b.rgba[i]));
  return sum / static_cast<double>(a.rgba.size());
}

std::span<const std::byte> span(const std::vector<std::byte>& v) {
  return {v.data(), v.size()};
}

TEST(ImageCodec, PngIsLosslessWithAlpha) {
  const Image image = pattern(64, 48, /*alpha=*/true);
  Result<std::vector<std::byte>> png = encodeImage(image, {.format = ImageFormat::kPng});
  ASSERT_TRUE(png.ok());
  EXPECT_EQ(imageFormatOf(*png), ImageFormat::kPng);
  Result<Image> back = decodeImage(span(*png), "mem.png");
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->width, 64u);
  EXPECT_EQ(back->height, 48u);
  EXPECT_EQ(back->rgba, image.rgba);
}

TEST(ImageCodec, JpegAndWebpStayCloseAtHighQuality) {
  const Image image = pattern(96, 64);
  for (ImageFormat format : {ImageFormat::kJpeg, ImageFormat::kWebp}) {
    Result<std::vector<std::byte>> encoded = encodeImage(image, {.format = format, .quality = 95});
    ASSERT_TRUE(encoded.ok());
    EXPECT_EQ(imageFormatOf(*encoded), format);
    Result<Image> back = decodeImage(span(*encoded), "mem");
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->width, 96u);
    EXPECT_LT(meanError(*back, image), 6.0) << imageFormatName(format);
    // Lower quality is smaller.
    Result<std::vector<std::byte>> small = encodeImage(image, {.format = format, .quality = 20});
    ASSERT_TRUE(small.ok());
    EXPECT_LT(small->size(), encoded->size()) << imageFormatName(format);
  }
}

TEST(ImageCodec, ProbeReadsTheHeaderOfFilesAndEmbeddedBytes) {
  test::TempDir dir;
  const Image image = pattern(40, 30);
  Result<std::vector<std::byte>> jpeg = encodeImage(image, {.format = ImageFormat::kJpeg});
  ASSERT_TRUE(jpeg.ok());
  const std::string path = dir.file("photo.jpg");
  test::writeFile(path,
                  std::string_view(reinterpret_cast<const char*>(jpeg->data()), jpeg->size()));
  ImageSource file{.name = "photo.jpg", .path = path};
  ASSERT_TRUE(probeImage(file).ok());
  EXPECT_EQ(file.format, ImageFormat::kJpeg);
  EXPECT_EQ(file.width, 40u);
  EXPECT_EQ(file.height, 30u);
  EXPECT_EQ(file.channels, 3u);

  Result<std::vector<std::byte>> png =
      encodeImage(pattern(8, 9, true), {.format = ImageFormat::kPng});
  ASSERT_TRUE(png.ok());
  ImageSource embedded{.name = "image 0", .bytes = *png};
  ASSERT_TRUE(probeImage(embedded).ok());
  EXPECT_EQ(embedded.format, ImageFormat::kPng);
  EXPECT_EQ(embedded.width, 8u);
  EXPECT_TRUE(embedded.hasAlpha());
  Result<Image> decoded = decodeImage(embedded);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(decoded->height, 9u);
}

TEST(ImageCodec, TgaAndBmpDecodeExactly) {
  test::TempDir dir;
  const Image opaque = pattern(13, 7), clear = pattern(9, 5, true);
  test::writeFile(dir.file("a.TGA"), test::tgaOf(opaque, false));
  test::writeFile(dir.file("b.tga"), test::tgaOf(clear, true));
  test::writeFile(dir.file("c.bmp"), test::bmpOf(opaque));
  const std::vector<std::tuple<std::string, ImageFormat, const Image*, std::uint32_t>> cases = {
      {"a.TGA", ImageFormat::kTga, &opaque, 3},
      {"b.tga", ImageFormat::kTga, &clear, 4},
      {"c.bmp", ImageFormat::kBmp, &opaque, 3}};
  for (const auto& [name, format, expected, channels] : cases) {
    ImageSource file{.name = name, .path = dir.file(name)};
    ASSERT_TRUE(probeImage(file).ok()) << name;
    EXPECT_EQ(file.format, format) << name;
    EXPECT_EQ(file.width, expected->width) << name;
    EXPECT_EQ(file.height, expected->height) << name;
    EXPECT_EQ(file.channels, channels) << name;
    Result<Image> decoded = decodeImage(file);
    ASSERT_TRUE(decoded.ok()) << name << ": " << decoded.error().message;
    EXPECT_EQ(decoded->rgba, expected->rgba) << name;
  }
  // A TGA has no signature: bytes named otherwise are not taken for one, and a .tga that
  // is not one (an unknown image type) is refused naming it.
  const std::string bytes = test::tgaOf(opaque, false);
  ImageSource unnamed{.name = "image 3",
                      .bytes = std::vector<std::byte>(
                          reinterpret_cast<const std::byte*>(bytes.data()),
                          reinterpret_cast<const std::byte*>(bytes.data()) + bytes.size())};
  EXPECT_FALSE(probeImage(unnamed).ok());
  // A BMP of no rows (stb decodes it as an empty image) is refused.
  std::string empty = test::bmpOf(opaque);
  std::fill(empty.begin() + 22, empty.begin() + 26, '\0');
  const Result<Image> none = decodeImage(
      std::span(reinterpret_cast<const std::byte*>(empty.data()), empty.size()), "empty.bmp");
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.error().message.find("no texels"), std::string::npos) << none.error().message;
  std::string broken = bytes;
  broken[2] = 7;
  test::writeFile(dir.file("broken.tga"), broken);
  ImageSource bad{.name = "broken.tga", .path = dir.file("broken.tga")};
  const Status refused = probeImage(bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("broken.tga"), std::string::npos);
}

TEST(ImageCodec, MissingGarbageAndCutShortImagesAreRefusedByName) {
  test::TempDir dir;
  ImageSource missing{.name = "gone.jpg", .path = dir.file("gone.jpg")};
  Status status = probeImage(missing);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.error().kind, ErrorKind::kBadInput);
  EXPECT_NE(status.error().message.find("gone.jpg"), std::string::npos);

  ImageSource garbage{.name = "notes.png", .bytes = {std::byte{'h'}, std::byte{'i'}}};
  status = probeImage(garbage);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("not a JPEG, PNG, WebP, BMP or TGA"), std::string::npos);

  // A JPEG cut in half decodes to grey rows in libjpeg: refused here instead.
  Result<std::vector<std::byte>> jpeg =
      encodeImage(pattern(64, 64), {.format = ImageFormat::kJpeg});
  ASSERT_TRUE(jpeg.ok());
  const std::vector<std::byte> half(jpeg->begin(),
                                    jpeg->begin() + static_cast<long>(jpeg->size() / 2));
  Result<Image> cut = decodeImage(span(half), "half.jpg");
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.error().message.find("half.jpg"), std::string::npos);
  // A PNG likewise.
  Result<std::vector<std::byte>> png = encodeImage(pattern(64, 64), {.format = ImageFormat::kPng});
  ASSERT_TRUE(png.ok());
  const std::vector<std::byte> cutPng(png->begin(),
                                      png->begin() + static_cast<long>(png->size() / 2));
  EXPECT_FALSE(decodeImage(span(cutPng), "half.png").ok());
}

TEST(ImageCodec, ImagesOverThePixelLimitAreRefusedBeforeDecoding) {
  Result<std::vector<std::byte>> jpeg =
      encodeImage(pattern(100, 100), {.format = ImageFormat::kJpeg});
  ASSERT_TRUE(jpeg.ok());
  Result<Image> refused = decodeImage(span(*jpeg), "big.jpg", /*maxPixels=*/9'999);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("big.jpg"), std::string::npos);
  EXPECT_TRUE(decodeImage(span(*jpeg), "big.jpg", 10'000).ok());
}

}  // namespace
}  // namespace lodforge
