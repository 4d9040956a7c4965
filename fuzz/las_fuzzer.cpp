// The LAS reader on any bytes: either a bad-input error naming the file, or points whose every
// coordinate is finite, read to the end in batches of every size the header allows.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_check.h"
#include "lodforge/io/points/las_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);

  for (std::size_t batch : {std::size_t{1}, std::size_t{7}, std::size_t{1} << 16}) {
    Result<LasReader> reader = LasReader::fromMemory(bytes, "fuzz.las", batch);
    if (!reader) {
      fuzz::checkError(reader.error(), "fuzz.las");
      return 0;
    }
    std::uint64_t count = 0;
    fuzz::readPoints(*reader, "fuzz.las", [&](const PointBatch& points) {
      count += points.size();
      if (count > reader->header().pointCount) std::abort();
    });
  }
  return 0;
}
