// A textured input's images as mip pyramids on disk: each image decoded once, its levels (each
// half the last, averaged in linear light) written as raw RGBA8 blocks of 64 x 64 texels in a
// work file, and read back by region through a block cache of bounded size. A tile's texture
// is resampled from the blocks it needs, never from whole decoded images held in memory.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/image.h"
#include "lodforge/core/image_source.h"
#include "lodforge/core/material.h"
#include "lodforge/core/status.h"

namespace lodforge {

inline constexpr std::uint32_t kPyramidBlock = 64;

class TexturePyramid {
 public:
  // Decodes each image (one at a time) into `directory`/<index>.pyr. An image that cannot be
  // decoded is bad input naming it. `cacheBytes` bounds the blocks held for reading. With
  // `reuse` (a resumed run, whose images are the ones it started from), a pyramid file already
  // there of its full size is taken as it is: it was renamed into place only when complete.
  static Result<TexturePyramid> build(std::span<const ImageSource> images,
                                      const std::string& directory, std::uint64_t cacheBytes,
                                      bool reuse = false);
  TexturePyramid(TexturePyramid&&) noexcept;
  TexturePyramid& operator=(TexturePyramid&&) noexcept;
  ~TexturePyramid();

  std::size_t imageCount() const;
  // Levels of an image: level 0 is the image, the last 1 x 1.
  std::uint32_t levels(std::size_t image) const;
  std::uint32_t width(std::size_t image, std::uint32_t level) const;
  std::uint32_t height(std::size_t image, std::uint32_t level) const;
  // Texels [x, x + w) x [y, y + h) of a level into `out` (w * h RGBA8, rows top to bottom);
  // coordinates outside the image wrap as the modes say. Safe to call from several threads.
  Status read(std::size_t image, std::uint32_t level, std::int64_t x, std::int64_t y,
              std::uint32_t w, std::uint32_t h, TextureWrap wrapS, TextureWrap wrapT,
              std::uint8_t* out) const;
  // Bytes the block cache holds at most.
  std::uint64_t cacheBytes() const;

 private:
  struct State;
  explicit TexturePyramid(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

// One level down: each texel the linear-light mean of the 2 x 2 it covers (an odd last row or
// column repeats its edge). Width and height halve, rounded down, never below 1.
Image halveImage(const Image& image);

// A coordinate outside [0, size) wrapped as the mode says.
std::int64_t wrapTexel(std::int64_t x, std::int64_t size, TextureWrap wrap);

}  // namespace lodforge
