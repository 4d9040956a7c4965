#include "lodforge/io/image/stb_image.h"

#include <cstring>

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_BMP
#define STBI_ONLY_TGA
#define STBI_NO_STDIO
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
// GCC 12 sees the callback reader's buffer fields as maybe uninitialized in the BMP and TGA paths;
// only memory is ever read here (stbi_*_from_memory), which never takes that path.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <stb_image.h>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#include <stb_image_write.h>

namespace lodforge::stb {

bool imageInfo(std::span<const std::byte> bytes, int& width, int& height, int& channels,
               std::string& why) {
  if (stbi_info_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()),
                            static_cast<int>(bytes.size()), &width, &height, &channels))
    return true;
  why = stbi_failure_reason();
  return false;
}

bool decodeImage(std::span<const std::byte> bytes, int& width, int& height,
                 std::vector<std::uint8_t>& rgba, std::string& why) {
  int channels = 0;
  stbi_uc* pixels =
      stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()),
                            static_cast<int>(bytes.size()), &width, &height, &channels, 4);
  if (pixels == nullptr) {
    why = stbi_failure_reason();
    return false;
  }
  rgba.assign(pixels, pixels + std::size_t(width) * std::size_t(height) * 4);
  stbi_image_free(pixels);
  return true;
}

bool encodePng(const std::uint8_t* rgba, int width, int height,
               const std::function<void(const void*, int)>& sink) {
  return stbi_write_png_to_func(
             [](void* context, void* data, int size) {
               (*static_cast<const std::function<void(const void*, int)>*>(context))(data, size);
             },
             const_cast<std::function<void(const void*, int)>*>(&sink), width, height, 4, rgba,
             width * 4) != 0;
}

}  // namespace lodforge::stb
