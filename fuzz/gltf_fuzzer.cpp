#include <cstddef>
#include <cstdint>

#include "fuzz_check.h"
#include "lodforge/io/mesh/gltf_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  // Never touch the file system from fuzzed input (external buffer URIs).
  fuzz::check(readGltfFromMemory(bytes, "fuzz.glb", {.allowExternalFiles = false}), "fuzz.glb");
  return 0;
}
