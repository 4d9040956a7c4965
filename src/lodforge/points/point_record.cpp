#include "lodforge/points/point_record.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>

namespace lodforge {

namespace {

template <class T>
void put(std::byte*& at, const T& value) {
  std::memcpy(at, &value, sizeof value);
  at += sizeof value;
}

template <class T>
void take(const std::byte*& at, T& value) {
  std::memcpy(&value, at, sizeof value);
  at += sizeof value;
}

}  // namespace

PointRecordLayout PointRecordLayout::of(const PointCloudInfo& info, bool placed,
                                        RecordNormals normals) {
  PointRecordLayout layout;
  layout.gridded_ = info.grid.has_value() && !placed;
  if (layout.gridded_) {
    layout.grid_ = *info.grid;
    for (int k = 0; k < 3; ++k) layout.inverseScale_[k] = 1.0 / layout.grid_.scale[k];
  }
  layout.normals_ = info.hasNormals || normals != RecordNormals::kInput;
  // An input's own normals stay floats: the clustering reads them.
  layout.normalBytes_ = !info.hasNormals && normals == RecordNormals::kBytes;
  layout.colors_ = info.hasColors;
  // The extra fields have a file of their own.
  layout.attributes_ = (info.attributes & ~std::uint32_t{kAttrExtras}) != 0;
  layout.bytes_ = (layout.gridded_ ? 3 * sizeof(std::int32_t) : sizeof(Vec3d)) +
                  (layout.normals_ ? (layout.normalBytes_ ? 4 : sizeof(Vec3f)) : 0) +
                  (layout.colors_ ? sizeof(Rgba8) : 0) +
                  (layout.attributes_ ? sizeof(PointAttributes) : 0);
  return layout;
}

Status PointRecordLayout::encode(std::span<const CloudPoint> points, std::byte* out) const {
  for (const CloudPoint& p : points) {
    if (gridded_) {
      for (int k = 0; k < 3; ++k) {
        // Rounded by adding a half and truncating (one instruction, where nearbyint is a libm
        // call without SSE4.1); the check below catches any rounding that missed.
        const double t = (p.position[k] - grid_.offset[k]) * inverseScale_[k];
        const double n = t + (t < 0 ? -0.5 : 0.5);
        const bool inRange = n > -2147483649.0 && n < 2147483648.0;
        const auto integer = inRange ? static_cast<std::int32_t>(n) : 0;
        // As the LAS reader computes it: the same integer must give back the same double.
        if (!inRange ||
            static_cast<double>(integer) * grid_.scale[k] + grid_.offset[k] != p.position[k])
          return Error{ErrorKind::kInternal,
                       fmt::format("position {:.17g} is not on the input's grid (scale {}, "
                                   "offset {})",
                                   p.position[k], grid_.scale[k], grid_.offset[k])};
        put(out, integer);
      }
    } else {
      put(out, p.position);
    }
    if (normalBytes_) {
      const float axes[3] = {p.normal.x, p.normal.y, p.normal.z};
      std::array<std::int8_t, 4> packed{};
      for (std::size_t k = 0; k < 3; ++k)
        packed[k] =
            static_cast<std::int8_t>(std::clamp(roundToLong(axes[k] * 127.0f), -127L, 127L));
      put(out, packed);
    } else if (normals_) {
      put(out, p.normal);
    }
    if (colors_) put(out, p.color);
    if (attributes_) put(out, p.attributes);
  }
  return {};
}

void PointRecordLayout::decode(const std::byte* in, std::span<CloudPoint> points) const {
  for (CloudPoint& p : points) {
    p.position = position(in);
    in += gridded_ ? 3 * sizeof(std::int32_t) : sizeof(Vec3d);
    p.normal = Vec3f{};
    p.color = Rgba8{};
    p.attributes = PointAttributes{};
    if (normalBytes_) {
      std::array<std::int8_t, 4> packed;
      take(in, packed);
      p.normal = Vec3f{static_cast<float>(packed[0]), static_cast<float>(packed[1]),
                       static_cast<float>(packed[2])} /
                 127.0f;
    } else if (normals_) {
      take(in, p.normal);
    }
    if (colors_) take(in, p.color);
    if (attributes_) take(in, p.attributes);
  }
}

}  // namespace lodforge
