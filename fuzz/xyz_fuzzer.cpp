// The text point reader on any bytes: either a bad-input error naming the file and line, or
// finite points with matching attribute arrays and unit normals.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_check.h"
#include "lodforge/io/xyz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace lodforge;
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  const auto fail = [](const Error& e) { fuzz::checkError(e, "fuzz.xyz:"); };

  Result<XyzReader> reader = XyzReader::fromMemory(bytes, "fuzz.xyz", 5);
  if (!reader) {
    fail(reader.error());
    return 0;
  }
  PointBatch points;
  while (true) {
    Result<bool> more = reader->next(points);
    if (!more) {
      fail(more.error());
      break;
    }
    if (!*more) break;
    if (!points.colors.empty() && points.colors.size() != points.size()) std::abort();
    if (!points.normals.empty() && points.normals.size() != points.size()) std::abort();
    for (const Vec3d& p : points.positions)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
    for (const Vec3f& n : points.normals)
      if (std::abs(length(n) - 1) > 1e-3f) std::abort();
  }
  return 0;
}
