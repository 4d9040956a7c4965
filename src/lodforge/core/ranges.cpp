#include "lodforge/core/ranges.h"

#include <algorithm>
#include <cassert>
#include <cstddef>

namespace lodforge {

namespace {

// Merges sorted ranges less than or `gap` elements apart, in place.
void mergeUpTo(std::vector<ElementRange>& ranges, std::uint64_t gap) {
  std::size_t out = 0;
  for (const ElementRange& r : ranges) {
    if (out > 0 && r.begin <= ranges[out - 1].end + gap) {
      ranges[out - 1].end = std::max(ranges[out - 1].end, r.end);
    } else {
      ranges[out++] = r;
    }
  }
  ranges.resize(out);
}

}  // namespace

void mergeRanges(std::vector<ElementRange>& ranges, std::size_t maxRanges,
                 std::vector<std::uint64_t>& gaps) {
  assert(maxRanges > 0);
  std::sort(ranges.begin(), ranges.end(),
            [](const ElementRange& a, const ElementRange& b) { return a.begin < b.begin; });
  mergeUpTo(ranges, 0);
  if (ranges.size() <= maxRanges) return;
  // The (n - maxRanges)-th smallest gap: merging every gap up to it leaves at most maxRanges.
  gaps.resize(ranges.size() - 1);
  for (std::size_t k = 0; k + 1 < ranges.size(); ++k) gaps[k] = ranges[k + 1].begin - ranges[k].end;
  const std::size_t cut = ranges.size() - maxRanges - 1;
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(cut), gaps.end());
  mergeUpTo(ranges, gaps[cut]);
  assert(ranges.size() <= maxRanges);
}

}  // namespace lodforge
