#include "lodforge/core/image_source.h"

#include <array>
#include <cstring>

namespace lodforge {
namespace {

bool startsWith(std::span<const std::byte> bytes, std::size_t at, std::string_view signature) {
  return bytes.size() >= at + signature.size() &&
         std::memcmp(bytes.data() + at, signature.data(), signature.size()) == 0;
}

}  // namespace

ImageFormat imageFormatOf(std::span<const std::byte> header) {
  if (startsWith(header, 0, "\xFF\xD8\xFF")) return ImageFormat::kJpeg;
  if (startsWith(header, 0, "\x89PNG\r\n\x1A\n")) return ImageFormat::kPng;
  if (startsWith(header, 0, "RIFF") && startsWith(header, 8, "WEBP")) return ImageFormat::kWebp;
  return ImageFormat::kUnknown;
}

std::string_view mimeTypeOf(ImageFormat format) {
  switch (format) {
    case ImageFormat::kJpeg:
      return "image/jpeg";
    case ImageFormat::kPng:
      return "image/png";
    case ImageFormat::kWebp:
      return "image/webp";
    case ImageFormat::kUnknown:
      break;
  }
  return {};
}

ImageFormat imageFormatOfMimeType(std::string_view mimeType) {
  for (ImageFormat f : {ImageFormat::kJpeg, ImageFormat::kPng, ImageFormat::kWebp}) {
    if (mimeTypeOf(f) == mimeType) return f;
  }
  return ImageFormat::kUnknown;
}

std::string_view imageFormatName(ImageFormat format) {
  switch (format) {
    case ImageFormat::kJpeg:
      return "JPEG";
    case ImageFormat::kPng:
      return "PNG";
    case ImageFormat::kWebp:
      return "WebP";
    case ImageFormat::kUnknown:
      break;
  }
  return "unknown";
}

}  // namespace lodforge
