#include "serve_ranges.h"

namespace lodforge::cli {

ServedRanges serveRanges(const std::vector<RequestedRange>& requested, std::uint64_t size) {
  ServedRanges served;
  if (requested.empty()) return served;
  for (auto [first, last] : requested) {
    if (first < 0 && last < 0) continue;  // "bytes=-" names nothing
    if (first < 0) {                      // the last `last` bytes
      if (last == 0 || size == 0) continue;
      const std::uint64_t length = std::min(static_cast<std::uint64_t>(last), size);
      served.ranges.emplace_back(size - length, size - 1);
      continue;
    }
    const auto start = static_cast<std::uint64_t>(first);
    if (start >= size) continue;  // past the end
    const std::uint64_t end =
        last < 0 ? size - 1 : std::min(static_cast<std::uint64_t>(last), size - 1);
    if (end < start) continue;
    served.ranges.emplace_back(start, end);
  }
  served.satisfiable = !served.ranges.empty();
  return served;
}

}  // namespace lodforge::cli
