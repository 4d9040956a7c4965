// Runs of array elements to copy, as [begin, end) in elements: what changed in an array that a
// copy (the GPU's) must take again. Each range costs a call, so close ones are merged.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace lodforge {

struct ElementRange {
  std::uint64_t begin = 0, end = 0;
};

// Working memory of mergeRanges, kept between calls.
struct RangeScratch {
  std::vector<std::uint64_t> gaps;
  std::vector<std::uint32_t> order;
};

// Sorts `ranges` and merges those that touch or overlap, then closes the smallest gaps (the
// first of equal ones) until at most `maxRanges` (> 0) are left. The result covers every
// element the input covered, sorted with gaps between.
void mergeRanges(std::vector<ElementRange>& ranges, std::size_t maxRanges, RangeScratch& scratch);

}  // namespace lodforge
