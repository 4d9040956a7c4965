#include <cstddef>
#include <cstdint>

#include "fuzz_check.h"
#include "lodforge/io/mesh/obj_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  fuzz::check(readObjFromMemory(bytes, "fuzz.obj"), "fuzz.obj");
  return 0;
}
