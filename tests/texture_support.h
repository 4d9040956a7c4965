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

// Uncompressed TGA (true colour, top-left origin, BGR or BGRA) and 24-bit BMP (bottom-up rows
// padded to 4 bytes, BGR), written by hand: what exporters of OBJ and 3DS textures write.
inline std::string tgaOf(const Image& image, bool alpha) {
  std::string out(18, '\0');
  out[2] = 2;
  out[12] = static_cast<char>(image.width & 255), out[13] = static_cast<char>(image.width >> 8);
  out[14] = static_cast<char>(image.height & 255), out[15] = static_cast<char>(image.height >> 8);
  out[16] = alpha ? 32 : 24;
  out[17] = static_cast<char>(alpha ? 0x28 : 0x20);
  for (std::size_t i = 0; i < image.rgba.size(); i += 4) {
    out += {static_cast<char>(image.rgba[i + 2]), static_cast<char>(image.rgba[i + 1]),
            static_cast<char>(image.rgba[i])};
    if (alpha) out += static_cast<char>(image.rgba[i + 3]);
  }
  return out;
}

inline std::string bmpOf(const Image& image) {
  const std::uint32_t row = (image.width * 3 + 3) / 4 * 4, pixels = row * image.height;
  std::string out(54, '\0');
  const auto put32 = [&](std::size_t at, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) out[at + std::size_t(k)] = static_cast<char>((v >> (8 * k)) & 255);
  };
  out[0] = 'B', out[1] = 'M';
  put32(2, 54 + pixels), put32(10, 54), put32(14, 40), put32(18, image.width);
  put32(22, image.height), out[26] = 1, out[28] = 24, put32(34, pixels);
  for (std::uint32_t y = image.height; y-- > 0;) {
    std::string line;
    for (std::uint32_t x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.rgba.data() + 4 * (std::size_t{y} * image.width + x);
      line += {static_cast<char>(p[2]), static_cast<char>(p[1]), static_cast<char>(p[0])};
    }
    line.resize(row, '\0');
    out += line;
  }
  return out;
}

}  // namespace lodforge::test
