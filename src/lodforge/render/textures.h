// A textured package's images as OpenGL textures (one per image, mipmapped, with the wrap modes
// of the first material that uses it), decoded row by row and reduced by whole factors to at
// most kMaxRenderTextureSize a side, so 16 8K atlases take 16 x 64 MiB, not 16 x 256 MiB.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/simplify/package.h"

namespace lodforge {

inline constexpr std::uint32_t kMaxRenderTextureSize = 4096;

class PackageTextures {
 public:
  // Needs a current GL 4.5 context. A package without images gives an empty set.
  static Result<PackageTextures> load(const Package& package);
  PackageTextures() = default;  // no textures
  PackageTextures(PackageTextures&&) noexcept;
  PackageTextures& operator=(PackageTextures&&) noexcept;
  ~PackageTextures();

  bool empty() const { return textures_.empty(); }
  // The GL texture of image k (k < the package's image count).
  unsigned texture(std::size_t k) const { return textures_[k]; }
  // Object i's texture image, kNoImage when it has none.
  std::uint32_t objectImage(std::size_t i) const { return objectImage_[i]; }
  std::uint64_t bytes() const { return bytes_; }  // texels held, mipmaps included

 private:
  std::vector<unsigned> textures_;
  std::vector<std::uint32_t> objectImage_;
  std::uint64_t bytes_ = 0;
};

}  // namespace lodforge
