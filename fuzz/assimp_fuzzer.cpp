// The assimp wrapper on OFF and Collada input (the first byte picks which): what the converter
// makes of whatever scene assimp hands it. The other formats are assimp's own parsers, fuzzed
// upstream (OSS-Fuzz), not our code.
#include <cstddef>
#include <cstdint>

#include "fuzz_check.h"
#include "lodforge/io/mesh/assimp_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  if (size == 0) return 0;
  const char* name = (data[0] & 1) ? "fuzz.dae" : "fuzz.off";
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data + 1), size - 1);
  fuzz::check(readAssimpFromMemory(bytes, name), name);
  return 0;
}
