// Rows of a box of corners or cells shared between threads: a dense chunk's work is split by
// rows (y), each share doing the same points or cells in the same order, so any count of shares
// gives the same bits.
#pragma once

#include <algorithm>
#include <cassert>
#include <cstdint>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace lodforge {

// The threads to share rows between: `threads`, or the arena's for 0.
inline int rowShareThreads(int threads) {
  assert(threads >= 0);
  return threads == 0 ? std::max(1, tbb::this_task_arena::max_concurrency()) : threads;
}

// Splits rows [0, rows) into shares, four per thread (`threads`, 0: the arena's), and calls
// each(first, end) for every share, in parallel.
template <class F>
void forEachRowShare(std::uint32_t rows, int threads, F&& each) {
  threads = rowShareThreads(threads);
  const auto shares = std::min<std::uint32_t>(rows, static_cast<std::uint32_t>(4 * threads));
  tbb::parallel_for(std::uint32_t{0}, shares, [&](std::uint32_t s) {
    each(static_cast<std::uint32_t>(std::uint64_t{rows} * s / shares),
         static_cast<std::uint32_t>(std::uint64_t{rows} * (s + 1) / shares));
  });
}

}  // namespace lodforge
