#include "lodforge/core/image_source.h"

#include <array>
#include <cctype>
#include <cstring>
#include <string>

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
  if (startsWith(header, 0, "BM")) return ImageFormat::kBmp;
  return ImageFormat::kUnknown;
}

ImageFormat imageFormatOfName(std::string_view name) {
  if (name.size() < 4) return ImageFormat::kUnknown;
  std::string tail(name.substr(name.size() - 4));
  for (char& c : tail) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return tail == ".tga" ? ImageFormat::kTga : ImageFormat::kUnknown;
}

bool gltfImageFormat(ImageFormat format) {
  return format == ImageFormat::kJpeg || format == ImageFormat::kPng ||
         format == ImageFormat::kWebp;
}

std::string_view mimeTypeOf(ImageFormat format) {
  switch (format) {
    case ImageFormat::kJpeg:
      return "image/jpeg";
    case ImageFormat::kPng:
      return "image/png";
    case ImageFormat::kWebp:
      return "image/webp";
    case ImageFormat::kBmp:
      return "image/bmp";
    case ImageFormat::kTga:
      return "image/x-tga";
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
    case ImageFormat::kBmp:
      return "BMP";
    case ImageFormat::kTga:
      return "TGA";
    case ImageFormat::kUnknown:
      break;
  }
  return "unknown";
}

}  // namespace lodforge
