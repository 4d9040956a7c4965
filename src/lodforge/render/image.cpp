#include "lodforge/render/image.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>

#include "lodforge/core/file.h"
#include "lodforge/io/image/image_codec.h"
#include "lodforge/io/image/stb_image.h"

namespace lodforge {

Result<Image> readPng(const std::string& path) {
  auto file = MappedFile::open(path);
  if (!file) return file.status();
  return readPngFromMemory(file->bytes(), path);
}

Result<Image> readPngFromMemory(std::span<const std::byte> bytes, const std::string& name,
                                std::uint64_t maxPixels) {
  static constexpr std::array<unsigned char, 8> kSignature = {0x89, 'P',  'N',  'G',
                                                              '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < kSignature.size() ||
      std::memcmp(bytes.data(), kSignature.data(), kSignature.size()) != 0)
    return Error{ErrorKind::kBadInput,
                 fmt::format("{}: not a PNG (no PNG signature at byte 0)", name)};
  if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    return Error{ErrorKind::kBadInput, fmt::format("{}: PNG larger than 2 GiB", name)};
  LODFORGE_TRY(checkPngChunks(bytes, name));
  int width = 0, height = 0;
  std::string why;
  // The header's size before decoding: a few bytes must not make us allocate gigabytes.
  if (int channels = 0; !stb::imageInfo(bytes, width, height, channels, why))
    return Error{ErrorKind::kBadInput,
                 fmt::format("{}: cannot read the PNG header ({})", name, why)};
  if (width <= 0 || height <= 0 ||
      static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > maxPixels)
    return Error{ErrorKind::kBadInput,
                 fmt::format("{}: PNG of {}x{} pixels is larger than {} megapixels", name, width,
                             height, maxPixels / 1000000)};
  Image image;
  if (!stb::decodeImage(bytes, width, height, image.rgba, why))
    return Error{ErrorKind::kBadInput, fmt::format("{}: cannot decode PNG ({})", name, why)};
  image.width = static_cast<std::uint32_t>(width);
  image.height = static_cast<std::uint32_t>(height);
  return image;
}

Status writePng(const std::string& path, const Image& image) {
  assert(image.rgba.size() == image.pixelCount() * 4);
  auto file = OutputFile::create(path);
  if (!file) return file.status();
  Status status;
  const bool ok = stb::encodePng(image.rgba.data(), static_cast<int>(image.width),
                                 static_cast<int>(image.height), [&](const void* data, int size) {
                                   if (status.ok())
                                     status = file->write(data, static_cast<std::size_t>(size));
                                 });
  if (!status.ok()) return status;
  if (!ok) return Error{ErrorKind::kIo, fmt::format("{}: PNG encoding failed", path)};
  return file->commit();
}

namespace {

// sRGB to CIELAB (D65 white), as the CIE defines it.
struct Lab {
  float l, a, b;
};

struct LabTables {
  std::array<float, 256> linear;  // sRGB byte to linear light
  LabTables() {
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      linear[static_cast<std::size_t>(i)] =
          static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
  }
};

float labF(float t) {
  constexpr float kDelta = 6.0f / 29.0f;
  return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3 * kDelta * kDelta) + 4.0f / 29.0f;
}

Lab toLab(const LabTables& tables, const std::uint8_t* rgb) {
  const float r = tables.linear[rgb[0]], g = tables.linear[rgb[1]], b = tables.linear[rgb[2]];
  // Linear sRGB to XYZ (IEC 61966-2-1), divided by the D65 white point.
  const float x = (0.4124564f * r + 0.3575761f * g + 0.1804375f * b) / 0.95047f;
  const float y = 0.2126729f * r + 0.7151522f * g + 0.0721750f * b;
  const float z = (0.0193339f * r + 0.1191920f * g + 0.9503041f * b) / 1.08883f;
  const float fx = labF(x), fy = labF(y), fz = labF(z);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

}  // namespace

void deltaE76(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b,
              std::span<float> deltaE) {
  assert(a.size() == b.size() && a.size() == deltaE.size() * 4);
  static const LabTables tables;
  for (std::size_t i = 0; i < deltaE.size(); ++i) {
    const std::uint8_t* pa = &a[4 * i];
    const std::uint8_t* pb = &b[4 * i];
    if (pa[0] == pb[0] && pa[1] == pb[1] && pa[2] == pb[2]) {
      deltaE[i] = 0;  // most pixels of a LOD comparison: skip the cube roots
      continue;
    }
    const Lab la = toLab(tables, pa), lb = toLab(tables, pb);
    const float dl = la.l - lb.l, da = la.a - lb.a, db = la.b - lb.b;
    deltaE[i] = std::sqrt(dl * dl + da * da + db * db);
  }
}

ImageDifference compareImages(const Image& a, const Image& b, double threshold,
                              std::vector<float>* deltaE) {
  assert(a.width == b.width && a.height == b.height);
  std::vector<float> local;
  std::vector<float>& values = deltaE ? *deltaE : local;
  values.resize(a.pixelCount());
  deltaE76(a.rgba, b.rgba, values);
  ImageDifference d;
  d.pixels = a.pixelCount();
  double sum = 0, squared = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    sum += values[i];
    d.maxDeltaE = std::max(d.maxDeltaE, static_cast<double>(values[i]));
    d.pixelsAbove += values[i] > threshold ? 1u : 0u;
    for (std::size_t c = 0; c < 3; ++c) {
      const double e = static_cast<double>(a.rgba[4 * i + c]) - b.rgba[4 * i + c];
      squared += e * e;
    }
  }
  if (d.pixels > 0) {
    d.meanDeltaE = sum / static_cast<double>(d.pixels);
    d.shareAbove = static_cast<double>(d.pixelsAbove) / static_cast<double>(d.pixels);
    const double mse = squared / (3.0 * static_cast<double>(d.pixels));
    if (mse > 0) d.psnr = 10 * std::log10(255.0 * 255.0 / mse);
  }
  return d;
}

Image deltaEHeatMap(std::span<const float> deltaE, std::uint32_t width, std::uint32_t height) {
  assert(deltaE.size() == std::size_t{width} * height);
  struct Stop {
    float at, r, g, b;
  };
  static constexpr std::array<Stop, 4> kStops = {
      {{0, 0, 0, 0},
       {static_cast<float>(kJustNoticeableDeltaE), 40, 60, 200},
       {10, 220, 40, 40},
       {25, 255, 240, 0}}};
  Image image(width, height);
  for (std::size_t i = 0; i < deltaE.size(); ++i) {
    const float e = deltaE[i];
    std::size_t s = 1;
    while (s + 1 < kStops.size() && e > kStops[s].at) ++s;
    const Stop& lo = kStops[s - 1];
    const Stop& hi = kStops[s];
    const float t = std::clamp((e - lo.at) / (hi.at - lo.at), 0.0f, 1.0f);
    const auto mix = [&](float x, float y) {
      return static_cast<std::uint8_t>(std::lround(x + (y - x) * t));
    };
    image.rgba[4 * i + 0] = mix(lo.r, hi.r);
    image.rgba[4 * i + 1] = mix(lo.g, hi.g);
    image.rgba[4 * i + 2] = mix(lo.b, hi.b);
    image.rgba[4 * i + 3] = 255;
  }
  return image;
}

}  // namespace lodforge
