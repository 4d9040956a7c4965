// Decoded RGBA8 texels: a rendered frame, a texture read from its file, an atlas being baked.
#pragma once

#include <cstdint>
#include <vector>

namespace lodforge {

struct Image {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // 4 per pixel, rows top to bottom

  Image() = default;
  Image(std::uint32_t w, std::uint32_t h) : width(w), height(h), rgba(std::size_t{w} * h * 4) {}
  std::size_t pixelCount() const { return std::size_t{width} * height; }
};

}  // namespace lodforge
