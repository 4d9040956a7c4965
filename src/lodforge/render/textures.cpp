#include "lodforge/render/textures.h"

#include <algorithm>
#include <bit>
#include <utility>

#include <epoxy/gl.h>

#include "lodforge/core/image.h"
#include "lodforge/io/image/image_codec.h"

namespace lodforge {

namespace {

// The image's texels averaged over `factor` x `factor` blocks, decoded a row at a time.
Result<Image> decodeReduced(const ImageSource& source) {
  Image out;
  std::uint32_t factor = 1, width = 0;
  std::vector<std::uint32_t> sums;
  std::uint32_t row = 0;
  const auto begin = [&](std::uint32_t w, std::uint32_t h) -> Status {
    while (std::max(w, h) > factor * kMaxRenderTextureSize) factor *= 2;
    width = w;
    out = Image((w + factor - 1) / factor, (h + factor - 1) / factor);
    sums.assign(std::size_t{out.width} * 4, 0);
    return {};
  };
  const auto flush = [&](std::uint32_t rows) {
    const std::uint32_t y = (row - 1) / factor;
    for (std::uint32_t x = 0; x < out.width; ++x) {
      const std::uint32_t columns = std::min(factor, width - x * factor);
      for (std::size_t c = 0; c < 4; ++c) {
        std::uint32_t& sum = sums[4 * std::size_t{x} + c];
        out.rgba[(std::size_t{y} * out.width + x) * 4 + c] =
            static_cast<std::uint8_t>((sum + columns * rows / 2) / (columns * rows));
        sum = 0;
      }
    }
  };
  const auto take = [&](const std::uint8_t* texels) -> Status {
    for (std::uint32_t x = 0; x < width; ++x)
      for (std::size_t c = 0; c < 4; ++c)
        sums[4 * std::size_t{x / factor} + c] += texels[4 * x + c];
    ++row;
    if (row % factor == 0) flush(factor);
    return {};
  };
  LODFORGE_TRY(decodeImageRows(source, kMaxTexturePixels, begin, take));
  if (row % factor != 0) flush(row % factor);
  return out;
}

GLint wrapOf(TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::kMirror:
      return GL_MIRRORED_REPEAT;
    case TextureWrap::kClamp:
      return GL_CLAMP_TO_EDGE;
    case TextureWrap::kRepeat:
      break;
  }
  return GL_REPEAT;
}

// A mipmapped texture of the image (glTF's sampler: linear, mipmapped, the material's wraps).
unsigned makeTexture(const Image& image, const Material& material, std::uint64_t& bytes) {
  GLuint texture = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  const auto levels = static_cast<GLsizei>(std::bit_width(std::max(image.width, image.height)));
  glTextureStorage2D(texture, levels, GL_RGBA8, static_cast<GLsizei>(image.width),
                     static_cast<GLsizei>(image.height));
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(texture, 0, 0, 0, static_cast<GLsizei>(image.width),
                      static_cast<GLsizei>(image.height), GL_RGBA, GL_UNSIGNED_BYTE,
                      image.rgba.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);  // GL's default, for whoever uploads next
  glGenerateTextureMipmap(texture);
  glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_S, wrapOf(material.wrapS));
  glTextureParameteri(texture, GL_TEXTURE_WRAP_T, wrapOf(material.wrapT));
  bytes += image.rgba.size() * 4 / 3;
  return texture;
}

}  // namespace

Result<PackageTextures> PackageTextures::load(const Package& package) {
  PackageTextures out;
  out.objectImage_.assign(package.objectCount(), kNoImage);
  if (package.imageCount() == 0) return out;
  // Each image's first material, for its wraps.
  std::vector<Material> materials(package.imageCount());
  for (std::size_t m = package.materialCount(); m-- > 0;) {
    const Material material = package.material(m);
    if (material.baseColorImage != kNoImage) materials[material.baseColorImage] = material;
  }
  for (std::size_t i = 0; i < package.objectCount(); ++i) {
    const std::uint32_t m = package.objectMaterial(i);
    if (m != kNoMaterial) out.objectImage_[i] = package.material(m).baseColorImage;
  }
  for (std::size_t k = 0; k < package.imageCount(); ++k) {
    Result<Image> image = decodeReduced(package.image(k));
    if (!image) return image.status();
    out.textures_.push_back(makeTexture(*image, materials[k], out.bytes_));
  }
  return out;
}

PackageTextures::PackageTextures(PackageTextures&& o) noexcept {
  *this = std::move(o);
}
PackageTextures& PackageTextures::operator=(PackageTextures&& o) noexcept {
  std::swap(textures_, o.textures_);
  std::swap(objectImage_, o.objectImage_);
  std::swap(bytes_, o.bytes_);
  return *this;
}
PackageTextures::~PackageTextures() {
  if (!textures_.empty())
    glDeleteTextures(static_cast<GLsizei>(textures_.size()), textures_.data());
}

}  // namespace lodforge
