#include <cstddef>
#include <cstdint>

#include "fuzz_check.h"
#include "lodforge/io/mesh/ply_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  // Strict, then salvaging with tiny batches (exercises batch edges and truncation recovery)
  // and packing the other vertex properties as extra fields.
  fuzz::check(readPlyFromMemory(bytes, "fuzz.ply"), "fuzz.ply");
  PlyReadOptions options;
  options.batchSize = 3;
  options.salvageTruncated = true;
  options.readExtras = true;
  fuzz::check(readPlyFromMemory(bytes, "fuzz.ply", options), "fuzz.ply");
  return 0;
}
