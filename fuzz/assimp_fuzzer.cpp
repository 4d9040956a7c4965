// The assimp wrapper on OFF, Collada and IFC input (the first byte picks which, modulo 3): what
// the converter makes of whatever scene assimp hands it, an IFC cut short among them. The other
// formats are assimp's own parsers, fuzzed upstream (OSS-Fuzz), not our code.
#include <cstddef>
#include <cstdint>

#include "fuzz_check.h"
#include "lodforge/io/mesh/assimp_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  if (size == 0) return 0;
  static const char* const kNames[] = {"fuzz.off", "fuzz.dae", "fuzz.ifc"};
  const char* name = kNames[data[0] % 3];
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data + 1), size - 1);
  fuzz::check(readAssimpFromMemory(bytes, name), name);
  return 0;
}
