#include "lodforge/render/shader.h"

#include <cassert>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include <epoxy/gl.h>

namespace lodforge {

Program::~Program() {
  if (id_) glDeleteProgram(id_);
}

Result<Program> Program::link(std::initializer_list<Stage> stages) {
  Program program;
  program.id_ = glCreateProgram();
  std::vector<GLuint> shaders;
  Status status;
  for (const Stage& stage : stages) {
    const GLuint shader = glCreateShader(stage.type);
    shaders.push_back(shader);
    const char* text = stage.source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      std::string log(4096, '\0');
      GLsizei length = 0;
      glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), &length, log.data());
      log.resize(static_cast<std::size_t>(length));
      status = Error{ErrorKind::kInternal, fmt::format("shader compile error: {}", log)};
      break;
    }
    glAttachShader(program.id_, shader);
  }
  if (status.ok()) {
    glLinkProgram(program.id_);
    GLint ok = 0;
    glGetProgramiv(program.id_, GL_LINK_STATUS, &ok);
    if (!ok) {
      std::string log(4096, '\0');
      GLsizei length = 0;
      glGetProgramInfoLog(program.id_, static_cast<GLsizei>(log.size()), &length, log.data());
      log.resize(static_cast<std::size_t>(length));
      status = Error{ErrorKind::kInternal, fmt::format("shader link error: {}", log)};
    }
  }
  for (GLuint shader : shaders) glDeleteShader(shader);
  if (!status.ok()) return status;
  return program;
}

std::uint64_t uploadRanges(unsigned buffer, std::span<const std::byte> array,
                           std::uint64_t elementBytes, std::span<const ElementRange> ranges) {
  std::uint64_t bytes = 0;
  for (const ElementRange& r : ranges) {
    if (r.end == r.begin) continue;
    const std::uint64_t offset = r.begin * elementBytes, size = (r.end - r.begin) * elementBytes;
    assert(offset + size <= array.size());
    glNamedBufferSubData(buffer, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(size),
                         array.data() + offset);
    bytes += size;
  }
  return bytes;
}

unsigned makeBuffer(std::uint64_t bytes, const void* data, unsigned flags) {
  GLuint buffer = 0;
  glCreateBuffers(1, &buffer);
  // GL reads the whole store from `data`: a padded store needs a padded copy.
  std::vector<std::byte> padded;
  if (data != nullptr && bytes < 16) {
    padded.resize(16);
    std::memcpy(padded.data(), data, bytes);
    data = padded.data();
  }
  glNamedBufferStorage(buffer, static_cast<GLsizeiptr>(std::max<std::uint64_t>(bytes, 16)), data,
                       flags);
  return buffer;
}

void dispatchElements(std::uint64_t elements) {
  constexpr std::uint64_t kGroupSize = 256, kMaxGroupsX = 65535;
  const std::uint64_t groups = (elements + kGroupSize - 1) / kGroupSize;
  if (groups == 0) return;
  const std::uint64_t x = std::min(groups, kMaxGroupsX);
  glDispatchCompute(static_cast<GLuint>(x), static_cast<GLuint>((groups + x - 1) / x), 1);
}

std::vector<std::uint32_t> readBufferWords(unsigned buffer, std::size_t words) {
  std::vector<std::uint32_t> out(words);
  if (words) glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(words * 4), out.data());
  return out;
}

}  // namespace lodforge
