#include <gtest/gtest.h>

#include "lodforge/core/image_source.h"
#include "test_support.h"

namespace lodforge {
namespace {

TEST(ImageSource, FormatsAreKnownByTheirSignatures) {
  using namespace std::literals;
  EXPECT_EQ(imageFormatOf(test::bytesOf("\xFF\xD8\xFF\xE0....")), ImageFormat::kJpeg);
  EXPECT_EQ(imageFormatOf(test::bytesOf("\x89PNG\r\n\x1A\n....")), ImageFormat::kPng);
  EXPECT_EQ(imageFormatOf(test::bytesOf("RIFF\x10\0\0\0WEBPVP8 "sv)), ImageFormat::kWebp);
  EXPECT_EQ(imageFormatOf(test::bytesOf("RIFF\x10\0\0\0WAVEfmt "sv)), ImageFormat::kUnknown);
  EXPECT_EQ(imageFormatOf(test::bytesOf("GIF89a")), ImageFormat::kUnknown);
  EXPECT_EQ(imageFormatOf(test::bytesOf("\xFF\xD8")), ImageFormat::kUnknown);  // too short
}

TEST(ImageSource, MimeTypesGoBothWays) {
  for (ImageFormat f : {ImageFormat::kJpeg, ImageFormat::kPng, ImageFormat::kWebp})
    EXPECT_EQ(imageFormatOfMimeType(mimeTypeOf(f)), f) << imageFormatName(f);
  EXPECT_EQ(imageFormatOfMimeType("image/ktx2"), ImageFormat::kUnknown);
  EXPECT_TRUE(mimeTypeOf(ImageFormat::kUnknown).empty());
}

TEST(ImageSource, AlphaAndDecodedSizeFollowTheHeader) {
  ImageSource image;
  image.width = 4096;
  image.height = 2048;
  image.channels = 3;
  EXPECT_FALSE(image.hasAlpha());
  EXPECT_EQ(image.decodedBytes(), 4096u * 2048u * 4u);
  image.channels = 2;
  EXPECT_TRUE(image.hasAlpha());
  EXPECT_TRUE(image.embedded());
  image.path = "a.png";
  EXPECT_FALSE(image.embedded());
}

}  // namespace
}  // namespace lodforge
