// Exact positions as hash keys, for welding what is bit-identical (weldVertices in core/mesh.cpp,
// weldExact in tiling/): each coordinate's bits with -0 folded into +0, mixed into 64 bits, so
// positions that compare equal hash equal.
#pragma once

#include <bit>
#include <cstdint>

#include "lodforge/core/math.h"

namespace lodforge {

// The bits of a coordinate, -0 as +0 (they compare equal, so they must hash equal).
constexpr std::uint64_t exactBits(double v) {
  return v == 0 ? 0 : std::bit_cast<std::uint64_t>(v);
}

constexpr std::uint64_t hashExactPosition(const Vec3d& p) {
  std::uint64_t h = exactBits(p.x) * 0x9E3779B97F4A7C15ull;
  h = (h ^ (h >> 29) ^ exactBits(p.y)) * 0xBF58476D1CE4E5B9ull;
  h = (h ^ (h >> 32) ^ exactBits(p.z)) * 0x94D049BB133111EBull;
  return h ^ (h >> 31);
}

// A float position hashes as the double it is exactly.
inline std::uint64_t hashExactPosition(const Vec3f& p) {
  return hashExactPosition(toDouble(p));
}

}  // namespace lodforge
