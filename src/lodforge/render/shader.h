// A linked GLSL program; compile and link errors come back with the driver's log.
#pragma once

#include <initializer_list>
#include <utility>

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

}  // namespace lodforge
