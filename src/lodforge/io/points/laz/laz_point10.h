// The 20-byte POINT10 record (LAS formats 0–5) as the LAZ codecs see it: fields by name, packed
// back to the record's bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "lodforge/io/points/record_field.h"

namespace lodforge {

struct LazPoint10 {
  std::int32_t x = 0, y = 0, z = 0;
  std::uint16_t intensity = 0;
  std::uint8_t flags = 0;  // return number (bits 0–2), returns (3–5), scan direction, edge
  std::uint8_t classification = 0;
  std::uint8_t scanAngle = 0;  // the signed rank's byte
  std::uint8_t userData = 0;
  std::uint16_t pointSource = 0;

  std::uint32_t returnNumber() const { return flags & 7u; }
  std::uint32_t numberOfReturns() const { return (flags >> 3) & 7u; }
  std::uint32_t scanDirection() const { return (flags >> 6) & 1u; }

  static LazPoint10 unpack(const std::byte* r) {
    LazPoint10 p;
    p.x = loadField<std::int32_t>(r);
    p.y = loadField<std::int32_t>(r + 4);
    p.z = loadField<std::int32_t>(r + 8);
    p.intensity = loadField<std::uint16_t>(r + 12);
    p.flags = static_cast<std::uint8_t>(r[14]);
    p.classification = static_cast<std::uint8_t>(r[15]);
    p.scanAngle = static_cast<std::uint8_t>(r[16]);
    p.userData = static_cast<std::uint8_t>(r[17]);
    p.pointSource = loadField<std::uint16_t>(r + 18);
    return p;
  }
  void pack(std::byte* r) const {
    std::memcpy(r, &x, 4);
    std::memcpy(r + 4, &y, 4);
    std::memcpy(r + 8, &z, 4);
    std::memcpy(r + 12, &intensity, 2);
    r[14] = static_cast<std::byte>(flags);
    r[15] = static_cast<std::byte>(classification);
    r[16] = static_cast<std::byte>(scanAngle);
    r[17] = static_cast<std::byte>(userData);
    std::memcpy(r + 18, &pointSource, 2);
  }
};

}  // namespace lodforge
