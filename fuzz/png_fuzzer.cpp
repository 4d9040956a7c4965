// The PNG reader `lodforge compare` uses, and the texture decoders (JPEG, PNG, WebP) behind
// every textured model: an image of the size the header states, or a bad-input error naming
// the file.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "lodforge/io/image/image_codec.h"
#include "lodforge/render/image.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  // 4 megapixels: enough for every code path, small enough that 2,000 inputs a second fit in RAM.
  ImageSource source{.name = "fuzz.img", .bytes = {bytes.begin(), bytes.end()}};
  const Status probed = probeImage(source);
  const auto texels = decodeImage(bytes, "fuzz.img", 4'000'000);
  if (texels.ok() && (texels->rgba.size() != texels->pixelCount() * 4 || !probed.ok() ||
                      texels->width != source.width || texels->height != source.height))
    std::abort();
  for (const Error* e :
       {probed.ok() ? nullptr : &probed.error(), texels.ok() ? nullptr : &texels.error()})
    if (e && (e->kind != ErrorKind::kBadInput || e->message.rfind("fuzz.img", 0) != 0)) {
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
