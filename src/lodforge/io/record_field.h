// A field of a binary record (LAS, LAZ) read from wherever it lies: copied, since record fields
// are not aligned. LAS and LAZ are little-endian, as every machine we build for is.
#pragma once

#include <cstddef>
#include <cstring>

namespace lodforge {

template <class T>
T loadField(const std::byte* at) {
  T value;
  std::memcpy(&value, at, sizeof value);
  return value;
}

}  // namespace lodforge
