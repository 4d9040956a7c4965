// The text point reader on any bytes: either a bad-input error naming the file and line, or
// finite points with matching attribute arrays and unit normals.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_check.h"
#include "lodforge/io/points/xyz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);

  Result<XyzReader> reader = XyzReader::fromMemory(bytes, "fuzz.xyz", 5);
  if (!reader) {
    fuzz::checkError(reader.error(), "fuzz.xyz:");
    return 0;
  }
  fuzz::readPoints(*reader, "fuzz.xyz:", [](const PointBatch&) {});
  return 0;
}
