// Texture images for the tests: a small patterned PNG, as bytes or written to a file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "lodforge/io/image/image_codec.h"
#include "test_support.h"

namespace lodforge::test {

inline void writeBytes(const std::string& path, std::span<const std::byte> bytes) {
  writeFile(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

// A PNG of `width` x `height` texels of a fixed pattern.
inline std::vector<std::byte> patternPng(std::uint32_t width, std::uint32_t height) {
  Image image(width, height);
  for (std::size_t i = 0; i < image.rgba.size(); ++i)
    image.rgba[i] = static_cast<std::uint8_t>(i * 7);
  Result<std::vector<std::byte>> png = encodeImage(image, {.format = ImageFormat::kPng});
  EXPECT_TRUE(png.ok());
  return png.ok() ? *png : std::vector<std::byte>{};
}

// The same written to `path` (its folder made).
inline void writePatternPng(const std::string& path, std::uint32_t width = 16,
                            std::uint32_t height = 8) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  writeBytes(path, patternPng(width, height));
}

}  // namespace lodforge::test
