// The package reader on any bytes: either a bad-input error naming the file, or a package whose
// every object re-forms at its simplest and fullest levels without leaving its bounds.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "lodforge/simplify/extract.h"
#include "lodforge/simplify/package.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  // Packages are mapped page-aligned; give the reader the same alignment.
  std::vector<std::uint64_t> aligned(size / 8 + 1);
  std::memcpy(aligned.data(), data, size);
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(aligned.data()), size);
  for (bool verify : {true, false}) {
    Result<Package> package = Package::fromBytes(bytes, "fuzz.lfp", {.verifyChecksums = verify});
    if (!package) {
      if (package.error().kind != ErrorKind::kBadInput ||
          package.error().message.rfind("fuzz.lfp", 0) != 0) {
        std::fprintf(stderr, "unexpected error: %s\n", package.error().message.c_str());
        std::abort();
      }
      continue;
    }
    for (double ratio : {0.0, 0.5, 1.0}) {
      const Model model = extractModel(*package, vertexCountsForRatio(*package, ratio));
      if (!isConsistent(model)) std::abort();
    }
  }
  return 0;
}
