#include "lodforge/tiling/normal_codec.h"

#include <cmath>

namespace lodforge {

std::uint32_t encodeNormal(Vec3f n) {
  const float sum = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  if (!(sum > 0)) return 0;  // unknown: decodes to +z
  float u = n.x / sum, v = n.y / sum;
  if (n.z < 0) {
    const float fu = (1 - std::abs(v)) * (u >= 0 ? 1.0f : -1.0f);
    const float fv = (1 - std::abs(u)) * (v >= 0 ? 1.0f : -1.0f);
    u = fu, v = fv;
  }
  const auto snorm = [](float x) {
    return static_cast<std::uint16_t>(static_cast<std::int16_t>(roundToLong(x * 32767.0f)));
  };
  return static_cast<std::uint32_t>(snorm(u)) | static_cast<std::uint32_t>(snorm(v)) << 16;
}

Vec3f decodeNormal(std::uint32_t packed) {
  const float u = static_cast<float>(static_cast<std::int16_t>(packed & 0xFFFF)) / 32767.0f;
  const float v = static_cast<float>(static_cast<std::int16_t>(packed >> 16)) / 32767.0f;
  Vec3f n{u, v, 1 - std::abs(u) - std::abs(v)};
  if (n.z < 0) {
    n.x = (1 - std::abs(v)) * (u >= 0 ? 1.0f : -1.0f);
    n.y = (1 - std::abs(u)) * (v >= 0 ? 1.0f : -1.0f);
  }
  return normalizeOr(n, Vec3f{0, 0, 1});
}

}  // namespace lodforge
