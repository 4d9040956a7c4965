// A field of a binary record (LAS, LAZ) read from wherever it lies: copied, since record fields
// are not aligned. LAS and LAZ are little-endian, as every machine we build for is.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <string>

namespace lodforge {

template <class T>
T loadField(const std::byte* at) {
  T value;
  std::memcpy(&value, at, sizeof value);
  return value;
}

// A fixed-size text field (a LAS header's or record's): up to the first NUL, trailing spaces
// dropped.
inline std::string loadText(const std::byte* at, std::size_t size) {
  std::string s(reinterpret_cast<const char*>(at), size);
  s.erase(std::find(s.begin(), s.end(), '\0'), s.end());
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

}  // namespace lodforge
