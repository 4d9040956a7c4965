#include "lodforge/io/image/image_codec.h"

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <jpeglib.h>
#include <webp/decode.h>
#include <webp/encode.h>

#include "lodforge/core/file.h"
#include "lodforge/io/image/stb_image.h"

namespace lodforge {
namespace {

std::string describe(const ImageSource& image) {
  return image.embedded() ? image.name : image.path;
}

// libjpeg reports a fatal error by calling error_exit, which must not return: it jumps back to
// the decoder's or encoder's setjmp (only plain data lives between the two).
struct JpegError {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void jpegErrorExit(j_common_ptr info) {
  auto* error = reinterpret_cast<JpegError*>(info->err);
  (*info->err->format_message)(info, error->message);
  std::longjmp(error->jump, 1);
}

// A warning (data cut short or corrupt, which libjpeg decodes as grey) keeps its message: the
// decoder then fails, so damage is never drawn silently. Trace messages (level > 0) are dropped.
void jpegWarning(j_common_ptr info, int level) {
  if (level >= 0) return;
  auto* error = reinterpret_cast<JpegError*>(info->err);
  if (error->manager.num_warnings++ == 0) (*info->err->format_message)(info, error->message);
}

// libjpeg's error manager routed to `error`: errors jump to its setjmp, warnings are kept. (The
// setjmp itself stays in each caller: the frame it marks must still be live when libjpeg jumps.)
jpeg_error_mgr* jpegErrors(JpegError& error) {
  jpeg_error_mgr* manager = jpeg_std_error(&error.manager);
  error.manager.error_exit = jpegErrorExit;
  error.manager.emit_message = jpegWarning;
  return manager;
}

// Streams a JPEG's rows (from memory or a file) to `row`; libjpeg's errors jump back here, past
// libjpeg's frames only. The callbacks' status is kept in `failed`.
bool decodeJpegRows(std::span<const std::byte> bytes, std::FILE* file, std::uint64_t maxPixels,
                    const std::function<Status(std::uint32_t, std::uint32_t)>& begin,
                    const std::function<Status(const std::uint8_t*)>& row, JpegError& error,
                    Status& failed, std::vector<std::uint8_t>& scanline) {
  // (Everything this function changes after setjmp lives in the caller: a local changed there
  // would hold no defined value after the jump.)
  jpeg_decompress_struct info;
  info.err = jpegErrors(error);
  if (setjmp(error.jump)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  if (file != nullptr) {
    jpeg_stdio_src(&info, file);
  } else {
    jpeg_mem_src(&info, reinterpret_cast<const unsigned char*>(bytes.data()),
                 static_cast<unsigned long>(bytes.size()));
  }
  jpeg_read_header(&info, TRUE);
  if (std::uint64_t{info.image_width} * info.image_height > maxPixels) {
    std::snprintf(error.message, sizeof error.message, "%ux%u pixels is more than %llu megapixels",
                  info.image_width, info.image_height,
                  static_cast<unsigned long long>(maxPixels / 1000000));
    jpeg_destroy_decompress(&info);
    return false;
  }
  info.out_color_space = JCS_EXT_RGBA;
  jpeg_start_decompress(&info);
  failed = begin(info.output_width, info.output_height);
  scanline.resize(std::size_t{info.output_width} * 4);
  while (failed.ok() && info.output_scanline < info.output_height) {
    JSAMPROW at = scanline.data();
    jpeg_read_scanlines(&info, &at, 1);
    // Damage shows as a warning: stop at it rather than hand on grey rows.
    if (error.manager.num_warnings > 0) break;
    failed = row(scanline.data());
  }
  if (failed.ok() && error.manager.num_warnings == 0) jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return error.manager.num_warnings == 0;
}

// A JPEG's size and components from its header (libjpeg reads up to the frame header).
bool readJpegHeader(std::span<const std::byte> bytes, int& width, int& height, int& channels,
                    JpegError& error) {
  jpeg_decompress_struct info;
  info.err = jpegErrors(error);
  if (setjmp(error.jump)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, reinterpret_cast<const unsigned char*>(bytes.data()),
               static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&info, TRUE);
  width = static_cast<int>(info.image_width);
  height = static_cast<int>(info.image_height);
  channels = info.num_components;
  jpeg_destroy_decompress(&info);
  return error.manager.num_warnings == 0;
}

// A whole JPEG: its rows (decodeJpegRows) gathered into one image.
Result<Image> decodeJpeg(std::span<const std::byte> bytes, const std::string& name,
                         std::uint64_t maxPixels) {
  Image image;
  std::size_t row = 0;
  JpegError error{};
  Status failed;
  std::vector<std::uint8_t> scanline;
  const bool ok = decodeJpegRows(
      bytes, nullptr, maxPixels,
      [&](std::uint32_t width, std::uint32_t height) -> Status {
        image = Image(width, height);
        return {};
      },
      [&](const std::uint8_t* pixels) -> Status {
        std::copy_n(pixels, std::size_t{image.width} * 4,
                    image.rgba.data() + row++ * image.width * 4);
        return {};
      },
      error, failed, scanline);
  LODFORGE_TRY(failed);
  if (!ok) return badInput(name, fmt::format("cannot decode the JPEG image ({})", error.message));
  return image;
}

Result<Image> decodeWebp(std::span<const std::byte> bytes, const std::string& name,
                         std::uint64_t maxPixels) {
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  int width = 0, height = 0;
  if (!WebPGetInfo(data, bytes.size(), &width, &height))
    return badInput(name, "cannot read the WebP header");
  if (static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > maxPixels)
    return badInput(name, fmt::format("WebP image of {}x{} pixels is too large", width, height));
  Image image(static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height));
  if (!WebPDecodeRGBAInto(data, bytes.size(), image.rgba.data(), image.rgba.size(), width * 4))
    return badInput(name, "cannot decode the WebP image");
  return image;
}

std::uint32_t bigEndian32(const std::byte* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 |
         std::uint32_t(p[3]);
}

// The chunk structure (length, type, data, CRC) must fit the file: stb trusts an IDAT's length
// and would allocate up to 2 GiB for a few bytes of input.
Status pngChunksFit(std::span<const std::byte> bytes, const std::string& name) {
  std::size_t at = 8;
  while (at < bytes.size()) {
    if (bytes.size() - at < 12)
      return Error{ErrorKind::kBadInput,
                   fmt::format("{}: PNG chunk at byte {} is cut off (12 bytes of length, type and "
                               "CRC needed, {} left)",
                               name, at, bytes.size() - at)};
    const std::uint32_t length = bigEndian32(bytes.data() + at);
    if (length > bytes.size() - at - 12)
      return Error{ErrorKind::kBadInput,
                   fmt::format("{}: PNG chunk at byte {} claims {} bytes of data, beyond the end "
                               "of the file ({} bytes)",
                               name, at, length, bytes.size())};
    const bool end = std::memcmp(bytes.data() + at + 4, "IEND", 4) == 0;
    at += 12 + std::size_t{length};
    if (end) return {};
  }
  return Error{ErrorKind::kBadInput,
               fmt::format("{}: PNG ends at byte {} without an IEND chunk", name, bytes.size())};
}

Result<Image> decodeStb(std::span<const std::byte> bytes, const std::string& name,
                        std::uint64_t maxPixels) {
  if (imageFormatOf(bytes) == ImageFormat::kPng) LODFORGE_TRY(pngChunksFit(bytes, name));
  int width = 0, height = 0, channels = 0;
  std::string why;
  if (!stb::imageInfo(bytes, width, height, channels, why))
    return badInput(name, fmt::format("cannot read the image header ({})", why));
  // (stb reads a BMP of no rows as an empty image: none is a texture.)
  if (width <= 0 || height <= 0)
    return badInput(name, fmt::format("image of {}x{} pixels has no texels", width, height));
  if (static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > maxPixels)
    return badInput(name, fmt::format("image of {}x{} pixels is too large", width, height));
  Image image;
  if (!stb::decodeImage(bytes, width, height, image.rgba, why))
    return badInput(name, fmt::format("cannot decode the image ({})", why));
  image.width = static_cast<std::uint32_t>(width);
  image.height = static_cast<std::uint32_t>(height);
  return image;
}

bool encodeJpegInto(const Image& image, int quality, const std::string& comment,
                    unsigned char*& out, unsigned long& size, JpegError& error) {
  jpeg_compress_struct info;
  info.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = jpegErrorExit;
  if (setjmp(error.jump)) {
    jpeg_destroy_compress(&info);
    return false;
  }
  jpeg_create_compress(&info);
  jpeg_mem_dest(&info, &out, &size);
  info.image_width = image.width;
  info.image_height = image.height;
  info.input_components = 4;
  info.in_color_space = JCS_EXT_RGBA;
  jpeg_set_defaults(&info);
  jpeg_set_quality(&info, quality, TRUE);
  jpeg_start_compress(&info, TRUE);
  if (!comment.empty())
    jpeg_write_marker(&info, JPEG_COM, reinterpret_cast<const JOCTET*>(comment.data()),
                      static_cast<unsigned>(comment.size()));
  while (info.next_scanline < info.image_height) {
    auto* row =
        const_cast<JSAMPROW>(image.rgba.data() + std::size_t{info.next_scanline} * image.width * 4);
    jpeg_write_scanlines(&info, &row, 1);
  }
  jpeg_finish_compress(&info);
  jpeg_destroy_compress(&info);
  return true;
}

std::vector<std::byte> copyOf(const void* data, std::size_t size) {
  std::vector<std::byte> bytes(size);
  if (size != 0) std::memcpy(bytes.data(), data, size);
  return bytes;
}

// What a header says, from the first bytes of the image (enough for every format but a JPEG
// whose frame header follows a large EXIF block: then the whole file is read).
Status probeBytes(ImageSource& image, std::span<const std::byte> bytes) {
  image.format = imageFormatOf(bytes);
  if (image.format == ImageFormat::kUnknown)
    image.format = imageFormatOfName(image.embedded() ? image.name : image.path);
  int width = 0, height = 0, channels = 0;
  std::string why = "not a JPEG, PNG, WebP, BMP or TGA image";
  bool ok = false;
  if (image.format == ImageFormat::kWebp) {
    WebPBitstreamFeatures features;
    ok = WebPGetFeatures(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(),
                         &features) == VP8_STATUS_OK;
    width = features.width;
    height = features.height;
    channels = features.has_alpha ? 4 : 3;
    why = "cannot read the WebP header";
  } else if (image.format == ImageFormat::kJpeg) {
    JpegError error{};
    ok = readJpegHeader(bytes, width, height, channels, error);
    why = fmt::format("cannot read the JPEG header ({})", error.message);
  } else if (image.format != ImageFormat::kUnknown) {  // PNG, BMP, TGA: stb
    ok = bytes.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max()) &&
         stb::imageInfo(bytes, width, height, channels, why);
  }
  if (!ok || width <= 0 || height <= 0)
    return badInput(describe(image), fmt::format("texture image: {}", why));
  image.width = static_cast<std::uint32_t>(width);
  image.height = static_cast<std::uint32_t>(height);
  image.channels = static_cast<std::uint32_t>(channels);
  return {};
}

}  // namespace

Status checkPngChunks(std::span<const std::byte> bytes, const std::string& name) {
  return pngChunksFit(bytes, name);
}

Result<std::vector<std::byte>> imageBytes(const ImageSource& image) {
  if (image.embedded()) return image.bytes;
  return readFileBytes(image.path);
}

Status probeImage(ImageSource& image) {
  if (image.embedded()) return probeBytes(image, image.bytes);
  std::FILE* file = std::fopen(image.path.c_str(), "rb");
  if (file == nullptr)
    return badInput(image.path, fmt::format("texture image: {}", std::strerror(errno)));
  std::vector<std::byte> head(std::size_t{1} << 16);
  head.resize(std::fread(head.data(), 1, head.size(), file));
  std::fclose(file);
  if (probeBytes(image, head).ok()) return {};
  if (head.size() < (std::size_t{1} << 16)) return probeBytes(image, head);
  Result<std::vector<std::byte>> whole = readFileBytes(image.path);
  if (!whole) return whole.status();
  return probeBytes(image, *whole);
}

namespace {

// The texels of an image of a known format.
Result<Image> decodeAs(std::span<const std::byte> bytes, ImageFormat format,
                       const std::string& name, std::uint64_t maxPixels) {
  switch (format) {
    case ImageFormat::kJpeg:
      return decodeJpeg(bytes, name, maxPixels);
    case ImageFormat::kPng:
      if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        return badInput(name, "PNG image larger than 2 GiB");
      return decodeStb(bytes, name, maxPixels);
    case ImageFormat::kWebp:
      return decodeWebp(bytes, name, maxPixels);
    case ImageFormat::kBmp:
    case ImageFormat::kTga:
      if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        return badInput(name, "texture image larger than 2 GiB");
      return decodeStb(bytes, name, maxPixels);
    case ImageFormat::kUnknown:
      break;
  }
  return badInput(name, "texture image: not a JPEG, PNG, WebP, BMP or TGA image");
}

}  // namespace

Result<Image> decodeImage(std::span<const std::byte> bytes, const std::string& name,
                          std::uint64_t maxPixels) {
  ImageFormat format = imageFormatOf(bytes);
  if (format == ImageFormat::kUnknown) format = imageFormatOfName(name);
  return decodeAs(bytes, format, name, maxPixels);
}

Result<Image> decodeImage(const ImageSource& image, std::uint64_t maxPixels) {
  Result<std::vector<std::byte>> bytes = imageBytes(image);
  if (!bytes) return bytes.status();
  ImageFormat format = imageFormatOf(*bytes);
  if (format == ImageFormat::kUnknown) format = image.format;  // a TGA, probed by its name
  return decodeAs(*bytes, format, describe(image), maxPixels);
}

Status decodeImageRows(const ImageSource& image, std::uint64_t maxPixels,
                       const std::function<Status(std::uint32_t, std::uint32_t)>& begin,
                       const std::function<Status(const std::uint8_t*)>& row) {
  if (image.format != ImageFormat::kJpeg) {
    Result<Image> whole = decodeImage(image, maxPixels);
    if (!whole) return whole.status();
    LODFORGE_TRY(begin(whole->width, whole->height));
    for (std::uint32_t y = 0; y < whole->height; ++y)
      LODFORGE_TRY(row(whole->rgba.data() + std::size_t{y} * whole->width * 4));
    return {};
  }
  std::FILE* file = nullptr;
  if (!image.embedded()) {
    file = std::fopen(image.path.c_str(), "rb");
    if (file == nullptr)
      return badInput(image.path, fmt::format("texture image: {}", std::strerror(errno)));
  }
  JpegError error{};
  Status failed;
  std::vector<std::uint8_t> scanline;
  const bool ok = decodeJpegRows(image.bytes, file, maxPixels, begin, row, error, failed, scanline);
  if (file != nullptr) std::fclose(file);
  LODFORGE_TRY(failed);
  if (!ok)
    return badInput(describe(image),
                    fmt::format("cannot decode the JPEG image ({})", error.message));
  return {};
}

Result<std::vector<std::byte>> encodeImage(const Image& image, const ImageEncodeOptions& options) {
  assert(image.rgba.size() == image.pixelCount() * 4 && image.width > 0 && image.height > 0);
  const int quality = std::clamp(options.quality, 1, 100);
  if (options.format == ImageFormat::kJpeg) {
    unsigned char* out = nullptr;
    unsigned long size = 0;
    JpegError error{};
    const bool ok = encodeJpegInto(image, quality, options.comment, out, size, error);
    std::vector<std::byte> bytes = ok ? copyOf(out, size) : std::vector<std::byte>();
    std::free(out);
    if (!ok) return Error{ErrorKind::kInternal, fmt::format("JPEG encoding: {}", error.message)};
    return bytes;
  }
  if (options.format == ImageFormat::kWebp) {
    std::uint8_t* out = nullptr;
    const std::size_t size = WebPEncodeRGBA(
        image.rgba.data(), static_cast<int>(image.width), static_cast<int>(image.height),
        static_cast<int>(image.width * 4), static_cast<float>(quality), &out);
    std::vector<std::byte> bytes = copyOf(out, size);
    WebPFree(out);
    if (size == 0) return Error{ErrorKind::kInternal, "WebP encoding failed"};
    return bytes;
  }
  std::vector<std::byte> bytes;
  const bool ok = stb::encodePng(image.rgba.data(), static_cast<int>(image.width),
                                 static_cast<int>(image.height), [&](const void* data, int size) {
                                   const auto* b = static_cast<const std::byte*>(data);
                                   bytes.insert(bytes.end(), b, b + size);
                                 });
  if (!ok) return Error{ErrorKind::kInternal, "PNG encoding failed"};
  return bytes;
}

}  // namespace lodforge
