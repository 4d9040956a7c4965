// Unit normals in 32 bits, octahedrally (Cigolle et al. 2014): 0.005 degrees at 16 bits per
// axis, a third of the bytes of three floats in every chunk-file corner (chunk_store.cpp).
#pragma once

#include <cstdint>

#include "lodforge/core/math.h"

namespace lodforge {

// A normal of no direction (zero, NaN) encodes as 0, which decodes to +z.
std::uint32_t encodeNormal(Vec3f n);
// A unit normal (+z where the encoding gives none).
Vec3f decodeNormal(std::uint32_t packed);

}  // namespace lodforge
