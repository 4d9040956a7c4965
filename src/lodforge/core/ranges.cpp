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

void mergeRanges(std::vector<ElementRange>& ranges, std::size_t maxRanges, RangeScratch& scratch) {
  assert(maxRanges > 0);
  std::sort(ranges.begin(), ranges.end(),
            [](const ElementRange& a, const ElementRange& b) { return a.begin < b.begin; });
  mergeUpTo(ranges, 0);
  if (ranges.size() <= maxRanges) return;
  // Close exactly the n - maxRanges smallest gaps, ties by position: an assembly of equal parts
  // has many equal gaps, and closing all of them could leave a few huge ranges.
  const std::size_t n = ranges.size(), close = n - maxRanges;
  std::vector<std::uint64_t>& gaps = scratch.gaps;
  std::vector<std::uint32_t>& order = scratch.order;
  gaps.resize(n - 1);
  order.resize(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    gaps[k] = ranges[k + 1].begin - ranges[k].end;
    order[k] = static_cast<std::uint32_t>(k);
  }
  std::nth_element(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(close - 1),
                   order.end(), [&](std::uint32_t a, std::uint32_t b) {
                     return gaps[a] != gaps[b] ? gaps[a] < gaps[b] : a < b;
                   });
  // Mark the closed gaps (a gap of 0 marks "closed": real gaps are positive here).
  for (std::size_t j = 0; j < close; ++j) gaps[order[j]] = 0;
  std::size_t out = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0 && gaps[k - 1] == 0) {
      ranges[out - 1].end = ranges[k].end;
    } else {
      ranges[out++] = ranges[k];
    }
  }
  ranges.resize(out);
  assert(ranges.size() == maxRanges);
}

}  // namespace lodforge
