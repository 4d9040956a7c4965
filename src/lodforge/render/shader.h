// A linked GLSL program; compile and link errors come back with the driver's log.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <utility>
#include <vector>

#include "lodforge/core/status.h"

namespace lodforge {

class Program {
 public:
  struct Stage {
    unsigned type;  // GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER
    const char* source;
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

// The first `words` 32-bit words of a GL buffer (tests, debugging).
std::vector<std::uint32_t> readBufferWords(unsigned buffer, std::size_t words);

}  // namespace lodforge
