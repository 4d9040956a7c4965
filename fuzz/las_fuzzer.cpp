// The LAS reader on any bytes: either a bad-input error naming the file, or points whose every
// coordinate is finite, read to the end in batches of every size the header allows.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_check.h"
#include "lodforge/io/las_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  const auto fail = [](const Error& e) { fuzz::checkError(e, "fuzz.las"); };

  for (std::size_t batch : {std::size_t{1}, std::size_t{7}, std::size_t{1} << 16}) {
    Result<LasReader> reader = LasReader::fromMemory(bytes, "fuzz.las", batch);
    if (!reader) {
      fail(reader.error());
      return 0;
    }
    PointBatch points;
    std::uint64_t count = 0;
    while (true) {
      Result<bool> more = reader->next(points);
      if (!more) {
        fail(more.error());
        break;
      }
      if (!*more) break;
      if (!points.colors.empty() && points.colors.size() != points.size()) std::abort();
      for (const Vec3d& p : points.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
      count += points.size();
      if (count > reader->header().pointCount) std::abort();
    }
  }
  return 0;
}
