#include "lodforge/render/point_renderer.h"

#include <algorithm>
#include <cmath>

#include <epoxy/gl.h>

#include "lodforge/render/renderer.h"
#include "lodforge/render/shader.h"

namespace lodforge {

namespace {

constexpr const char* kPointVertexShader = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec4 color;
layout(location = 3) in float radius;
uniform mat4 viewProjection;
uniform vec3 eye;
uniform vec3 forward;
uniform float pixelScale;
uniform float maxSplat;
out vec3 shade;
void main() {
  gl_Position = viewProjection * vec4(position, 1.0);
  float depth = max(dot(position - eye, forward), 1e-6);
  // The node's disc, projected: diameter = 2 r · pixels per unit at depth 1 / depth.
  gl_PointSize = clamp(2.0 * radius * pixelScale / depth, 1.0, maxSplat);
  // Headlight, both sides lit (estimated normals have no inside or outside).
  float light = 0.35 + 0.65 * abs(dot(normalize(normal), normalize(eye - position)));
  shade = color.rgb * light;
}
)";

constexpr const char* kPointFragmentShader = R"(#version 450 core
in vec3 shade;
out vec4 fragment;
void main() {
  vec2 p = gl_PointCoord * 2.0 - 1.0;
  if (dot(p, p) > 1.0) discard;  // round splats
  fragment = vec4(shade, 1.0);
}
)";

}  // namespace

struct PointRenderer::State {
  Program program;
  GLuint vertexArray = 0;
  GLuint buffers[4] = {0, 0, 0, 0};  // positions, normals, colours, radii
  std::size_t capacity = 0;          // splats the buffers hold
  std::size_t count = 0;
  Vec3d origin;
  std::uint64_t uploaded = 0;
  ~State() {
    for (GLuint b : buffers)
      if (b) glDeleteBuffers(1, &b);
    if (vertexArray) glDeleteVertexArrays(1, &vertexArray);
  }
};

PointRenderer::PointRenderer(std::unique_ptr<State> state) : state_(std::move(state)) {}
PointRenderer::PointRenderer(PointRenderer&&) noexcept = default;
PointRenderer& PointRenderer::operator=(PointRenderer&&) noexcept = default;
PointRenderer::~PointRenderer() = default;

Result<PointRenderer> PointRenderer::create() {
  auto state = std::make_unique<State>();
  Result<Program> program = Program::link(
      {{GL_VERTEX_SHADER, kPointVertexShader}, {GL_FRAGMENT_SHADER, kPointFragmentShader}});
  if (!program) return program.status();
  state->program = std::move(*program);
  glCreateVertexArrays(1, &state->vertexArray);
  const struct {
    GLint size;
    GLenum type;
    GLboolean normalized;
  } formats[4] = {{3, GL_FLOAT, GL_FALSE},
                  {3, GL_FLOAT, GL_FALSE},
                  {4, GL_UNSIGNED_BYTE, GL_TRUE},
                  {1, GL_FLOAT, GL_FALSE}};
  for (GLuint location = 0; location < 4; ++location) {
    glEnableVertexArrayAttrib(state->vertexArray, location);
    glVertexArrayAttribFormat(state->vertexArray, location, formats[location].size,
                              formats[location].type, formats[location].normalized, 0);
    glVertexArrayAttribBinding(state->vertexArray, location, location);
  }
  return PointRenderer(std::move(state));
}

void PointRenderer::upload(const PointSelection& selection) {
  State& s = *state_;
  s.count = selection.size();
  s.origin = selection.origin;
  if (s.count > s.capacity) {
    // Grow by half again so a moving fovea does not reallocate every frame.
    s.capacity = std::max<std::size_t>(1024, s.count + s.count / 2);
    const std::size_t sizes[4] = {sizeof(Vec3f), sizeof(Vec3f), sizeof(Rgba8), sizeof(float)};
    for (GLuint i = 0; i < 4; ++i) {
      if (s.buffers[i]) glDeleteBuffers(1, &s.buffers[i]);
      s.buffers[i] = makeBuffer(s.capacity * sizes[i]);
      glVertexArrayVertexBuffer(s.vertexArray, i, s.buffers[i], 0, static_cast<GLsizei>(sizes[i]));
    }
  }
  const auto put = [&](GLuint buffer, const auto& values) {
    const auto bytes = static_cast<GLsizeiptr>(values.size() * sizeof(values[0]));
    if (bytes > 0) glNamedBufferSubData(buffer, 0, bytes, values.data());
    s.uploaded += static_cast<std::uint64_t>(bytes);
  };
  put(s.buffers[0], selection.positions);
  put(s.buffers[1], selection.normals);
  put(s.buffers[2], selection.colors);
  put(s.buffers[3], selection.radii);
}

void PointRenderer::draw(const Camera& camera, const PointDrawOptions& options) const {
  const State& s = *state_;
  glEnable(GL_PROGRAM_POINT_SIZE);
  beginFrame(camera, options.background);
  if (s.count == 0) return;
  // Splat positions are relative to the selection's origin: so is the camera here.
  Camera local = camera;
  local.position = camera.position - s.origin;
  const GLuint p = s.program.id();
  useCameraProgram(p, local);
  glUniform3f(glGetUniformLocation(p, "forward"), static_cast<float>(camera.forward.x),
              static_cast<float>(camera.forward.y), static_cast<float>(camera.forward.z));
  glUniform1f(glGetUniformLocation(p, "pixelScale"), static_cast<float>(camera.pixelScale()));
  glUniform1f(glGetUniformLocation(p, "maxSplat"), options.maxSplatPixels);
  glBindVertexArray(s.vertexArray);
  glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(s.count));
  glBindVertexArray(0);
}

std::uint64_t PointRenderer::uploadedBytes() const {
  return state_->uploaded;
}

}  // namespace lodforge
