#include "lodforge/core/memory.h"

#include <malloc.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

#include "lodforge/core/units.h"

namespace lodforge {

namespace {
std::uint64_t statusField(const char* field) {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0;
  char line[256];
  std::uint64_t kib = 0;
  const std::size_t length = std::strlen(field);
  while (std::fgets(line, sizeof line, f)) {
    if (std::strncmp(line, field, length) == 0) {
      kib = std::strtoull(line + length, nullptr, 10);
      break;
    }
  }
  std::fclose(f);
  return kib * 1024;
}
}  // namespace

std::uint64_t physicalMemoryBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), pageSize = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && pageSize > 0
             ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(pageSize)
             : 0;
}

std::uint64_t currentRssBytes() {
  return statusField("VmRSS:");
}
std::uint64_t peakRssBytes() {
  return statusField("VmHWM:");
}

Status MemoryBudget::reserve(std::uint64_t bytes, const char* what) {
  std::uint64_t current = used_.load();
  do {
    if (limit_ != 0 && current + bytes > limit_) {
      return Error{
          ErrorKind::kLimit,
          fmt::format("{} needs {} but only {} of the {} memory limit is free", what,
                      formatBytes(bytes), formatBytes(limit_ - current), formatBytes(limit_))};
    }
  } while (!used_.compare_exchange_weak(current, current + bytes));
  return {};
}

void keepFreedMemoryForReuse() {
  constexpr int kKeep = 16 << 20;
  mallopt(M_MMAP_THRESHOLD, kKeep);
  mallopt(M_TRIM_THRESHOLD, kKeep);
}

}  // namespace lodforge
