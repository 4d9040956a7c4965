// Texture images in and out: what an image's header says (probeImage), its texels
// (decodeImage: JPEG through libjpeg-turbo, PNG through stb, WebP through libwebp) and texels
// encoded again (encodeImage). Every failure names the image and, for a file, its path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/image.h"
#include "lodforge/core/image_source.h"
#include "lodforge/core/status.h"

namespace lodforge {

// Larger images are refused before decoding: 16384 x 16384 is 268 megapixels.
inline constexpr std::uint64_t kMaxTexturePixels = 300'000'000;

// Fills `image`'s format, width, height and channels from its file's (or embedded bytes')
// header. kBadInput naming the image when it is missing, unreadable or not JPEG, PNG or WebP.
Status probeImage(ImageSource& image);
// A PNG's chunks (length, type, data, CRC) fit its bytes and end with IEND: stb trusts an
// IDAT's length and would allocate up to 2 GiB for a few bytes of input. kBadInput naming the
// chunk otherwise.
Status checkPngChunks(std::span<const std::byte> bytes, const std::string& name);
// The encoded bytes of an image: its embedded bytes, or its file read whole.
Result<std::vector<std::byte>> imageBytes(const ImageSource& image);
// The texels of an encoded image, as RGBA8 (grey and RGB gain alpha 255). `name` for messages.
Result<Image> decodeImage(std::span<const std::byte> bytes, const std::string& name,
                          std::uint64_t maxPixels = kMaxTexturePixels);
Result<Image> decodeImage(const ImageSource& image, std::uint64_t maxPixels = kMaxTexturePixels);

// The texels of an image row by row (RGBA8, top to bottom): `begin` gets the size first, then
// `row` each row. A JPEG is decoded as it is read (a few rows in memory, whatever its size);
// PNG and WebP are decoded whole first. A failure of `begin` or `row` stops decoding and is
// returned.
Status decodeImageRows(const ImageSource& image, std::uint64_t maxPixels,
                       const std::function<Status(std::uint32_t, std::uint32_t)>& begin,
                       const std::function<Status(const std::uint8_t*)>& row);

struct ImageEncodeOptions {
  ImageFormat format = ImageFormat::kJpeg;
  int quality = 90;       // JPEG and WebP, 1..100 (PNG is lossless)
  std::string comment{};  // JPEG: a COM marker with this text (empty: none)
};
// JPEG drops alpha (a texture with alpha goes to PNG or WebP: the caller decides).
Result<std::vector<std::byte>> encodeImage(const Image& image, const ImageEncodeOptions& options);

}  // namespace lodforge
