// The PNG reader `lodforge compare` uses, and the texture decoders (JPEG, PNG, WebP, BMP, TGA)
// behind every textured model: an image of the size the header states, or a bad-input error
// naming the file. An input with an odd first byte is named .tga (a TGA has no signature).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/render/image.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  // 4 megapixels: enough for every code path, small enough that 2,000 inputs a second fit in RAM.
  const std::string name = size > 0 && data[0] % 2 == 1 ? "fuzz.tga" : "fuzz.img";
  ImageSource source{.name = name, .bytes = {bytes.begin(), bytes.end()}};
  const Status probed = probeImage(source);
  const auto texels = decodeImage(bytes, name, 4'000'000);
  if (texels.ok() && (texels->rgba.size() != texels->pixelCount() * 4 || !probed.ok() ||
                      texels->width != source.width || texels->height != source.height)) {
    std::fprintf(stderr, "decoded %ux%u, probed %ux%u: %s\n", texels->width, texels->height,
                 source.width, source.height, probed.ok() ? "" : probed.error().message.c_str());
    std::abort();
  }
  for (const Error* e :
       {probed.ok() ? nullptr : &probed.error(), texels.ok() ? nullptr : &texels.error()})
    if (e && (e->kind != ErrorKind::kBadInput || e->message.rfind(name, 0) != 0)) {
      std::fprintf(stderr, "unexpected error: %s\n", e->message.c_str());
      std::abort();
    }
  const auto image = readPngFromMemory(bytes, "fuzz.png", 4'000'000);
  if (image.ok()) {
    if (image->rgba.size() != image->pixelCount() * 4 || image->pixelCount() == 0) std::abort();
    return 0;
  }
  if (image.error().kind != ErrorKind::kBadInput ||
      image.error().message.rfind("fuzz.png", 0) != 0) {
    std::fprintf(stderr, "unexpected error: %s\n", image.error().message.c_str());
    std::abort();
  }
  return 0;
}
