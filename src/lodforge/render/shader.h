// A linked GLSL program; compile and link errors come back with the driver's log.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "lodforge/core/ranges.h"
#include "lodforge/core/status.h"

namespace lodforge {

class Program {
 public:
  struct Stage {
    unsigned type;  // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER
    std::string source;
  };
  static Result<Program> link(std::initializer_list<Stage> stages);
  Program() = default;
  Program(Program&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  Program& operator=(Program&& o) noexcept {
    std::swap(id_, o.id_);
    return *this;
  }
  ~Program();
  unsigned id() const { return id_; }

 private:
  unsigned id_ = 0;
};

// A GL buffer of `bytes` (at least 16: a zero-size store is an error), filled from `data` if given.
unsigned makeBuffer(std::uint64_t bytes, const void* data = nullptr,
                    unsigned flags = 0x0100 /* GL_DYNAMIC_STORAGE_BIT */);

// Copies `ranges` of `array` (elements of `elementBytes` each) to the same offsets of a GL
// buffer; the bytes copied. How a copy on the GPU follows a changing array (runtime/stream.h).
std::uint64_t uploadRanges(unsigned buffer, std::span<const std::byte> array,
                           std::uint64_t elementBytes, std::span<const ElementRange> ranges);

// Compute shaders over `elements` items, 256 per group, groups spread over x and y past the
// 65,535 per dimension GL 4.5 guarantees. Shaders start with kElementGlsl to get the index.
void dispatchElements(std::uint64_t elements);

// GLSL shared by the compute shaders: elementIndex() for dispatchElements(), and owner(), the
// last row of `table` (binding 2, sorted by .x) whose .x is at most j — the binary search over
// prefix sums by which §3.2 finds the object an element belongs to.
constexpr const char* kElementGlsl = R"(#version 450 core
layout(local_size_x = 256) in;
layout(std430, binding = 2) readonly buffer Table { uvec4 table[]; };

uint elementIndex() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 256u + gl_LocalInvocationID.x;
}

uint owner(uint j, uint rows) {
  uint lo = 0u, hi = rows - 1u;
  while (lo < hi) {
    uint mid = (lo + hi + 1u) / 2u;
    if (table[mid].x <= j) lo = mid; else hi = mid - 1u;
  }
  return lo;
}
)";

// The first `words` 32-bit words of a GL buffer (tests, debugging).
std::vector<std::uint32_t> readBufferWords(unsigned buffer, std::size_t words);

}  // namespace lodforge
