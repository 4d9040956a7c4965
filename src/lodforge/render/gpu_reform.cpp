#include "lodforge/render/gpu_reform.h"

#include <algorithm>
#include <array>
#include <cassert>

#include <epoxy/gl.h>

#include "lodforge/render/shader.h"

namespace lodforge {

namespace {

// Algorithm 2, one invocation per triangle up to the last selected one.
// Per selected object in `table`: first triangle in the frame, ECol offset, first vertex in the
// frame, vc; a row with vc = 0 marks triangles that belong to no object (between slots).
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
  if (o.w == 0u) return;
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
  std::uint64_t sourceBytes = 0;  // a StreamBuffer's source triangles (a GpuStream has its own)
  std::vector<std::array<std::uint32_t, 4>> table;
  const Package* package = nullptr;
  std::uint64_t heldUpdate = 0;  // the StreamBuffer update the source buffer holds (0: none)
  std::vector<ElementRange> ranges, vertexRanges;  // vertexRanges: unused, the stream gives both
  std::uint64_t uploaded = 0;                      // by the last reform

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
  if (!capacity.arenaFitsGpuOffsets())
    return Error{ErrorKind::kUnsupported,
                 "GPU reformation addresses corners with 32-bit offsets: the stream's arena is "
                 "over 4 G of them; lower the budget or --gpu-memory"};
  auto program = Program::link({{GL_COMPUTE_SHADER, std::string(kElementGlsl) + kReformMain}});
  if (!program) return program.status();
  s->program = std::move(*program);
  // The package's ECol section is one array over all objects (each at its vertex offset).
  const std::uint32_t* ecol = package.objectCount() ? package.ecol(0).data() : nullptr;
  s->ecol = makeBuffer(vertices * sizeof(std::uint32_t), ecol, 0);         // immutable
  s->sourceBytes = capacity.arenaTriangles() * 3 * sizeof(std::uint32_t);  // on first use
  s->objectCapacity = 2 * package.objectCount() + 1;  // each object, and a skip row before it
  s->objects = makeBuffer(s->objectCapacity * 16);
  return GpuReformer(std::move(s));
}

GpuReformer::GpuReformer(std::unique_ptr<State> state) : state_(std::move(state)) {}

std::uint64_t GpuReformer::uploadedBytes() const {
  return state_->uploaded;
}
GpuReformer::GpuReformer(GpuReformer&&) noexcept = default;
GpuReformer& GpuReformer::operator=(GpuReformer&&) noexcept = default;
GpuReformer::~GpuReformer() = default;

void GpuReformer::reform(const StreamBuffer& buffer, unsigned indexBuffer) {
  State& s = *state_;
  const auto source = buffer.sourceTriangles();
  if (!s.source) s.source = makeBuffer(s.sourceBytes);
  // Only the source triangles the stream's update wrote, as the renderer sends its arrays.
  buffer.rangesSince(s.heldUpdate, StreamBuffer::kUploadRanges, s.vertexRanges, s.ranges);
  s.uploaded = uploadRanges(s.source, std::as_bytes(source), 3 * sizeof(std::uint32_t), s.ranges);
  s.heldUpdate = buffer.lastUpdate();
  run(state_->source,
      {buffer.vertexCounts(), buffer.triangleCounts(), buffer.slotOrder(), buffer.vertexStart(),
       buffer.triangleStart()},
      indexBuffer);
}

void GpuReformer::reform(const GpuStream& stream, unsigned indexBuffer) {
  state_->uploaded = 0;
  run(stream.sourceBuffer(),
      {stream.vertexCounts(),
       stream.triangleCounts(),
       {},
       stream.vertexStart(),
       stream.triangleStart()},
      indexBuffer);
}

void GpuReformer::run(unsigned sourceBuffer, const Objects& objects, unsigned indexBuffer) {
  State& s = *state_;
  // The frame's object table, by first triangle: objects with triangles, and a skip row (vc = 0)
  // wherever triangles follow that no object owns, so the search needs no tie rule.
  s.table.clear();
  std::uint32_t end = 0;  // past the last row's triangles
  const std::size_t n = objects.vertexCounts.size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = objects.order.empty() ? k : objects.order[k];
    const std::uint32_t triangles = objects.triangleCounts[i];
    if (triangles == 0) continue;
    const auto start = static_cast<std::uint32_t>(objects.triangleStart[i]);
    assert(start >= end);
    if (start > end) s.table.push_back({end, 0, 0, 0});
    s.table.push_back({start, static_cast<std::uint32_t>(s.package->object(i).vertexOffset),
                       static_cast<std::uint32_t>(objects.vertexStart[i]),
                       objects.vertexCounts[i]});
    end = start + triangles;
  }
  const std::uint64_t triangles = end;
  if (triangles == 0) return;
  assert(s.table.size() <= s.objectCapacity);
  glNamedBufferSubData(s.objects, 0, static_cast<GLsizeiptr>(s.table.size() * 16), s.table.data());
  s.uploaded += s.table.size() * 16;
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
