#include <cstddef>
#include <cstdint>

#include "fuzz_check.h"
#include "lodforge/io/mesh/stl_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  fuzz::check(readStlFromMemory(bytes, "fuzz.stl"), "fuzz.stl");
  return 0;
}
