#include "lodforge/render/gpu_reform.h"

#include <algorithm>
#include <array>

#include <epoxy/gl.h>

#include "lodforge/render/shader.h"

namespace lodforge {

namespace {

// Algorithm 2, one invocation per selected triangle.
// Per selected object in `table`: first triangle in the frame, ECol offset, first vertex in the
// frame, vc.
constexpr const char* kReformMain = R"(
layout(std430, binding = 0) readonly buffer Ecol { uint ecol[]; };      // every object, resident
layout(std430, binding = 1) readonly buffer Source { uint source[]; };  // object-local corners
layout(std430, binding = 3) writeonly buffer Indices { uint indices[]; };
uniform uint triangleCount;
uniform uint objectCount;

void main() {
  uint t = elementIndex();
  if (t >= triangleCount) return;
  uvec4 o = table[owner(t, objectCount)];
  for (uint k = 0u; k < 3u; ++k) {
    uint c = source[3u * t + k];
    while (c >= o.w) c = ecol[o.y + c];  // chains strictly decrease (Algorithm 1)
    indices[3u * t + k] = o.z + c;
  }
}
)";

}  // namespace

struct GpuReformer::State {
  Program program;
  GLuint ecol = 0, source = 0, objects = 0;
  std::uint64_t objectCapacity = 0;
  std::vector<std::array<std::uint32_t, 4>> table;
  const Package* package = nullptr;

  ~State() {
    for (GLuint b : {ecol, source, objects}) {
      if (b) glDeleteBuffers(1, &b);
    }
  }
};

Result<GpuReformer> GpuReformer::create(const Package& package, const StreamCapacity& capacity) {
  auto s = std::make_unique<State>();
  s->package = &package;
  const std::uint64_t vertices = package.header().vertexCount;
  if (vertices >= (std::uint64_t{1} << 32))
    return Error{ErrorKind::kUnsupported,
                 "GPU reformation addresses ECol with 32-bit offsets: this package has more than "
                 "4 G vertices; use the CPU path"};
  auto program = Program::link({{GL_COMPUTE_SHADER, std::string(kElementGlsl) + kReformMain}});
  if (!program) return program.status();
  s->program = std::move(*program);
  // The package's ECol section is one array over all objects (each at its vertex offset).
  const std::uint32_t* ecol = package.objectCount() ? package.ecol(0).data() : nullptr;
  s->ecol = makeBuffer(vertices * sizeof(std::uint32_t), ecol, 0);  // immutable
  s->source = makeBuffer(capacity.triangles * 3 * sizeof(std::uint32_t));
  s->objectCapacity = package.objectCount();
  s->objects = makeBuffer(s->objectCapacity * 16);
  return GpuReformer(std::move(s));
}

GpuReformer::GpuReformer(std::unique_ptr<State> state) : state_(std::move(state)) {}
GpuReformer::GpuReformer(GpuReformer&&) noexcept = default;
GpuReformer& GpuReformer::operator=(GpuReformer&&) noexcept = default;
GpuReformer::~GpuReformer() = default;

void GpuReformer::reform(const StreamBuffer& buffer, unsigned indexBuffer) {
  const auto source = buffer.sourceTriangles();
  glNamedBufferSubData(state_->source, 0, static_cast<GLsizeiptr>(source.size_bytes()),
                       source.data());
  run(state_->source, buffer.vertexCounts(), buffer.vertexStart(), buffer.triangleStart(),
      indexBuffer);
}

void GpuReformer::reform(const GpuStream& stream, unsigned indexBuffer) {
  run(stream.sourceBuffer(), stream.vertexCounts(), stream.vertexStart(), stream.triangleStart(),
      indexBuffer);
}

void GpuReformer::run(unsigned sourceBuffer, std::span<const std::uint32_t> counts,
                      std::span<const std::uint64_t> vertexStart,
                      std::span<const std::uint64_t> triangleStart, unsigned indexBuffer) {
  State& s = *state_;
  const std::uint64_t triangles = triangleStart.back();
  if (triangles == 0) return;
  // The frame's object table: only objects with triangles, so the search needs no tie rule.
  s.table.clear();
  for (std::size_t i = 0; i < counts.size(); ++i) {
    if (triangleStart[i + 1] == triangleStart[i]) continue;
    s.table.push_back({static_cast<std::uint32_t>(triangleStart[i]),
                       static_cast<std::uint32_t>(s.package->object(i).vertexOffset),
                       static_cast<std::uint32_t>(vertexStart[i]), counts[i]});
  }
  glNamedBufferSubData(s.objects, 0, static_cast<GLsizeiptr>(s.table.size() * 16), s.table.data());
  const GLuint p = s.program.id();
  glUseProgram(p);
  glUniform1ui(glGetUniformLocation(p, "triangleCount"), static_cast<GLuint>(triangles));
  glUniform1ui(glGetUniformLocation(p, "objectCount"), static_cast<GLuint>(s.table.size()));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, s.ecol);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, sourceBuffer);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s.objects);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, indexBuffer);
  dispatchElements(triangles);
  // The next draw reads the indices; a read-back reads the buffer.
  glMemoryBarrier(GL_ELEMENT_ARRAY_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

std::vector<std::uint32_t> GpuReformer::readIndices(unsigned indexBuffer, std::uint64_t triangles) {
  return readBufferWords(indexBuffer, 3 * triangles);
}

}  // namespace lodforge
