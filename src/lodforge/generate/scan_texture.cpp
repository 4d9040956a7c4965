#include "lodforge/generate/scan_texture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <fmt/format.h>
#include <stb_perlin.h>
#include <tbb/parallel_for.h>

#include "lodforge/core/file.h"
#include "lodforge/io/image/image_codec.h"

namespace lodforge {
namespace {

// What a generated atlas carries in its JPEG comment, so that a later run knows it as ours.
constexpr std::string_view kAtlasMark = "lodforge generate scan atlas";

float noise(double x, double y, int octave, std::uint64_t seed) {
  // stb's Perlin noise repeats every 256 units: offset each octave and the seed's stream.
  const auto s = static_cast<float>((seed * 37 + static_cast<std::uint64_t>(octave) * 101) % 211);
  return stb_perlin_noise3(static_cast<float>(std::fmod(x, 256.0)) + s,
                           static_cast<float>(std::fmod(y, 256.0)) + s * 0.5f, s, 0, 0, 0);
}

// Fractal noise in [-1, 1] about, wavelengths from `longest` metres down by halves.
float fractal(double x, double y, double longest, int octaves, std::uint64_t seed) {
  float sum = 0, amplitude = 0.5f;
  double f = 1.0 / longest;
  for (int o = 0; o < octaves; ++o, f *= 2, amplitude *= 0.55f)
    sum += amplitude * noise(x * f, y * f, o, seed);
  return sum;
}

// The ground's colour before detail: grass, dry grass, soil and rock patches by large-scale
// noise (smooth: drawn on a coarse grid and interpolated).
std::array<float, 3> patches(double x, double y, std::uint64_t seed) {
  const float patch = fractal(x, y, 160, 4, seed);
  const float dry = fractal(x + 911, y + 377, 60, 3, seed);
  const std::array<float, 3> grass{0.24f, 0.36f, 0.12f}, hay{0.55f, 0.50f, 0.28f},
      soil{0.42f, 0.31f, 0.20f}, rock{0.52f, 0.50f, 0.47f};
  const float w = std::clamp(0.5f + 1.5f * dry, 0.0f, 1.0f);
  const float r = std::clamp(2.5f * (patch - 0.15f), 0.0f, 1.0f);
  const float s = std::clamp(2.5f * (-patch - 0.2f), 0.0f, 1.0f);
  std::array<float, 3> c{};
  for (std::size_t k = 0; k < 3; ++k)
    c[k] = ((grass[k] * (1 - w) + hay[k] * w) * (1 - r) + rock[k] * r) * (1 - s) + soil[k] * s;
  return c;
}

// Grain at the texel: a hash of the texel, as a photo's noise.
float grain(std::uint64_t x, std::uint64_t y, std::uint64_t seed) {
  std::uint64_t h = (x * 0x9E3779B97F4A7C15ull) ^ (y * 0xC2B2AE3D27D4EB4Full) ^ seed;
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 29;
  return static_cast<float>(h & 0xFFFF) / 65535.0f - 0.5f;
}

}  // namespace

ScanAtlasLayout ScanAtlasLayout::of(std::uint32_t atlases, std::uint64_t columns,
                                    std::uint64_t rows) {
  ScanAtlasLayout layout;
  layout.columns = std::max<std::uint64_t>(columns, 1);
  layout.rows = std::max<std::uint64_t>(rows, 1);
  atlases = std::max(atlases, 1u);
  // The factor pair nearest a square.
  for (std::uint32_t a = 1; a * a <= atlases; ++a)
    if (atlases % a == 0) layout.across = a;
  layout.along = atlases / layout.across;
  layout.across =
      static_cast<std::uint32_t>(std::min<std::uint64_t>(layout.across, layout.columns));
  layout.along = static_cast<std::uint32_t>(std::min<std::uint64_t>(layout.along, layout.rows));
  return layout;
}

std::uint32_t ScanAtlasLayout::regionOf(std::uint64_t column, std::uint64_t row) const {
  const std::uint64_t a = std::min<std::uint64_t>(column * across / columns, across - 1);
  const std::uint64_t b = std::min<std::uint64_t>(row * along / rows, along - 1);
  return static_cast<std::uint32_t>(b * across + a);
}

std::array<std::uint64_t, 4> ScanAtlasLayout::cells(std::uint32_t region) const {
  const std::uint64_t a = region % across, b = region / across;
  // The inverse of regionOf: the first cell whose region index reaches a (or b).
  const auto first = [](std::uint64_t i, std::uint64_t n, std::uint64_t parts) {
    return (i * n + parts - 1) / parts;
  };
  return {first(a, columns, across), first(a + 1, columns, across), first(b, rows, along),
          b + 1 == along ? std::max(rows, first(b + 1, rows, along)) : first(b + 1, rows, along)};
}

Image drawScanAtlas(std::uint64_t seed, const ScanAtlasLayout& layout, std::uint32_t region,
                    double cell, std::uint32_t size) {
  const std::array<std::uint64_t, 4> cells = layout.cells(region);
  const double u0 = static_cast<double>(cells[0]) * cell, v0 = static_cast<double>(cells[2]) * cell;
  const double du = static_cast<double>(cells[1] - cells[0]) * cell / size;
  const double dv = static_cast<double>(cells[3] - cells[2]) * cell / size;
  // The patches on a grid of every 16th texel, interpolated between.
  constexpr std::uint32_t kStep = 16;
  const std::uint32_t grid = size / kStep + 2;
  std::vector<std::array<float, 3>> coarse(std::size_t{grid} * grid);
  tbb::parallel_for(std::uint32_t{0}, grid, [&](std::uint32_t j) {
    for (std::uint32_t i = 0; i < grid; ++i)
      coarse[std::size_t{j} * grid + i] = patches(u0 + i * kStep * du, v0 + j * kStep * dv, seed);
  });
  // The clumps' noise, a few texels across, repeats every 1,024 texels (stb's noise every 256
  // units, four texels a unit): drawn once for a tile of that size, not once a texel.
  const std::uint32_t period = std::min<std::uint32_t>(size, 1024);
  std::vector<float> clumps(std::size_t{period} * period);
  tbb::parallel_for(std::uint32_t{0}, period, [&](std::uint32_t y) {
    for (std::uint32_t x = 0; x < period; ++x) {
      const double wx = u0 + (x + 0.5) * du, wy = v0 + (y + 0.5) * dv;
      clumps[std::size_t{y} * period + x] = noise(wx / (4 * du), wy / (4 * dv), 9, seed);
    }
  });
  Image image(size, size);
  tbb::parallel_for(std::uint32_t{0}, size, [&](std::uint32_t y) {
    const std::uint32_t j = y / kStep;
    const float fy = static_cast<float>(y % kStep) / kStep;
    for (std::uint32_t x = 0; x < size; ++x) {
      const std::uint32_t i = x / kStep;
      const float fx = static_cast<float>(x % kStep) / kStep;
      const auto& a = coarse[std::size_t{j} * grid + i];
      const auto& b = coarse[std::size_t{j} * grid + i + 1];
      const auto& c = coarse[std::size_t{j + 1} * grid + i];
      const auto& d = coarse[std::size_t{j + 1} * grid + i + 1];
      // Detail: clumps a few texels across, then grain at the texel.
      const float detail = 0.35f * clumps[std::size_t{y % period} * period + x % period] +
                           0.25f * grain(cells[0] * size + x, cells[2] * size + y, seed);
      std::uint8_t* p = &image.rgba[4 * (std::size_t{y} * size + x)];
      for (std::size_t k = 0; k < 3; ++k) {
        const float base =
            (a[k] * (1 - fx) + b[k] * fx) * (1 - fy) + (c[k] * (1 - fx) + d[k] * fx) * fy;
        // Rounded half up (the value is not negative): what lround gives, without its call.
        p[k] =
            static_cast<std::uint8_t>(std::clamp(base * (1.0f + detail), 0.0f, 1.0f) * 255 + 0.5f);
      }
      p[3] = 255;
    }
  });
  return image;
}

std::string scanAtlasName(const std::string& plyPath, std::uint32_t region) {
  return fmt::format("{}_atlas_{:02}.jpg", std::filesystem::path(plyPath).stem().string(), region);
}

Status checkScanAtlasPlace(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return {};
  // The mark sits in the first bytes (after the start and JFIF markers).
  std::string head(256, '\0');
  std::FILE* in = std::fopen(path.c_str(), "rb");
  head.resize(in ? std::fread(head.data(), 1, head.size(), in) : 0);
  if (in) std::fclose(in);
  if (head.starts_with("\xFF\xD8") && head.find(kAtlasMark) != std::string::npos) return {};
  return Error{
      ErrorKind::kUsage,
      fmt::format("{}: exists and is not an atlas lodforge generated; not replaced", path)};
}

Status writeScanAtlas(const Image& image, const std::string& path) {
  LODFORGE_TRY(checkScanAtlasPlace(path));
  Result<std::vector<std::byte>> jpeg = encodeImage(
      image, {.format = ImageFormat::kJpeg, .quality = 90, .comment = std::string(kAtlasMark)});
  if (!jpeg) return jpeg.status();
  Result<OutputFile> file = OutputFile::create(path);
  if (!file) return file.status();
  LODFORGE_TRY(file->write(jpeg->data(), jpeg->size()));
  return file->commit();
}

}  // namespace lodforge
