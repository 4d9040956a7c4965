// Memory accounting: the process's resident size as the kernel sees it, and a budget that
// builders reserve from before they allocate big buffers.
#pragma once

#include <atomic>
#include <cstdint>

#include "lodforge/core/status.h"

namespace lodforge {

std::uint64_t physicalMemoryBytes();
std::uint64_t currentRssBytes();
std::uint64_t peakRssBytes();  // VmHWM: the high-water mark since the process started

// Keeps freed blocks of up to 16 MiB in the allocator instead of unmapping them (glibc's
// thresholds; its default returns most per-block buffers to the kernel, which then faults and
// zeroes them again for the next block). Point tiles of 20 M points: 6.9 → 4.9 s of system time.
void keepFreedMemoryForReuse();

class MemoryBudget {
 public:
  // limit 0 means unlimited.
  explicit MemoryBudget(std::uint64_t limitBytes = 0) : limit_(limitBytes) {}
  std::uint64_t limit() const { return limit_; }
  std::uint64_t used() const { return used_.load(); }
  // Reserves `bytes` or returns a kLimit error naming `what`.
  Status reserve(std::uint64_t bytes, const char* what);
  void release(std::uint64_t bytes) { used_.fetch_sub(bytes); }

 private:
  std::uint64_t limit_;
  std::atomic<std::uint64_t> used_{0};
};

}  // namespace lodforge
