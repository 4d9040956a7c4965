// A texture image a model refers to (Model::images): a file beside the input or bytes embedded
// in it, kept encoded (a model never holds decoded texels: a photogrammetry mesh has dozens of
// 8K atlases), with what its header says about it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lodforge {

// BMP and TGA come in through OBJ and assimp's formats; glTF holds only JPEG, PNG and WebP, so
// a GLB writer re-encodes them (gltfImageFormat).
enum class ImageFormat : std::uint8_t { kUnknown, kJpeg, kPng, kWebp, kBmp, kTga };

struct ImageSource {
  std::string name{};              // as the input names it: a file name, or "image 3"
  std::string path{};              // the file, resolved; empty when embedded
  std::vector<std::byte> bytes{};  // the encoded image when embedded; empty when a file
  ImageFormat format = ImageFormat::kUnknown;
  std::uint32_t width = 0, height = 0;
  std::uint32_t channels = 0;  // in the file: 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA

  bool embedded() const { return path.empty(); }
  bool hasAlpha() const { return channels == 2 || channels == 4; }
  // Bytes its texels take decoded as RGBA8 (what a viewer uploads, without mipmaps).
  std::uint64_t decodedBytes() const { return std::uint64_t{width} * height * 4; }
};

// The format an image's first bytes announce (JPEG, PNG, WebP and BMP signatures; a TGA has
// none, see imageFormatOfName).
ImageFormat imageFormatOf(std::span<const std::byte> header);
// kTga for a name ending in ".tga" (any case), kUnknown otherwise: a TGA is known by its name.
ImageFormat imageFormatOfName(std::string_view name);
// What glTF may hold: JPEG, PNG, or WebP (EXT_texture_webp).
bool gltfImageFormat(ImageFormat format);
// "image/jpeg", "image/png", "image/webp", "image/bmp", "image/x-tga"; empty for kUnknown.
std::string_view mimeTypeOf(ImageFormat format);
// The format of a glTF mimeType ("image/png"), kUnknown for any other.
ImageFormat imageFormatOfMimeType(std::string_view mimeType);
// "JPEG", "PNG", "WebP", "BMP", "TGA", "unknown".
std::string_view imageFormatName(ImageFormat format);

}  // namespace lodforge
