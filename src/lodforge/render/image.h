// RGBA8 images: PNG in and out (stb), and the image difference of the large-meshes paper —
// CIE76 ΔE per pixel in CIELAB (sRGB, D65) — with PSNR beside it.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/image.h"
#include "lodforge/core/status.h"

namespace lodforge {

// A PNG of any channel count becomes RGBA8; a file that is not a PNG is kBadInput naming it.
Result<Image> readPng(const std::string& path);
// Larger PNGs are refused before decoding (a frame of 16384 x 16384 is 268 megapixels).
constexpr std::uint64_t kMaxPngPixels = 300'000'000;
Result<Image> readPngFromMemory(std::span<const std::byte> bytes, const std::string& name,
                                std::uint64_t maxPixels = kMaxPngPixels);
// Written under a temporary name and renamed when complete.
Status writePng(const std::string& path, const Image& image);

// Kernel: CIE76 ΔE between the RGB of two RGBA8 pixel arrays (alpha ignored), per pixel.
void deltaE76(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b,
              std::span<float> deltaE);

// The large-meshes paper reports the share of pixels with ΔE above 2.3, the just noticeable
// difference.
constexpr double kJustNoticeableDeltaE = 2.3;

struct ImageDifference {
  std::uint64_t pixels = 0;
  std::uint64_t pixelsAbove = 0;  // ΔE > threshold
  double shareAbove = 0;          // pixelsAbove / pixels
  double meanDeltaE = 0, maxDeltaE = 0;
  double psnr = std::numeric_limits<double>::infinity();  // dB over RGB; infinite if equal
};

// The images must have the same size (callers check and report). `deltaE`, when given, receives
// the per-pixel values (for a heat map).
ImageDifference compareImages(const Image& a, const Image& b,
                              double threshold = kJustNoticeableDeltaE,
                              std::vector<float>* deltaE = nullptr);

// ΔE as colours: black at 0, blue at the threshold, red at 10, yellow from 25.
Image deltaEHeatMap(std::span<const float> deltaE, std::uint32_t width, std::uint32_t height);

}  // namespace lodforge
