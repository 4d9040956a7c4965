// What a generator wrote, for the command's summary and the benchmarks.
#pragma once

#include <cstdint>

namespace lodforge {

struct GenerateStats {
  std::uint64_t objects = 0;
  std::uint64_t vertices = 0;  // or points
  std::uint64_t triangles = 0;
  std::uint64_t bytes = 0;  // size of the file written
};

}  // namespace lodforge
