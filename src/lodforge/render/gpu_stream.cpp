#include "lodforge/render/gpu_stream.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cstring>
#include <vector>

#include <epoxy/gl.h>

#include "lodforge/render/shader.h"

namespace lodforge {

namespace {

// §3.3's reassembly, one invocation per destination element: element l of object i comes from
// the old copy while l < kept_i, else from the Δ ranges uploaded this frame.
// Per object present in the new frame, in `table`: new start, old start, kept count, start in
// Delta.
constexpr const char* kAssembleMain = R"(
layout(std430, binding = 0) readonly buffer Old { uint old[]; };
layout(std430, binding = 1) readonly buffer Delta { uint delta[]; };
layout(std430, binding = 3) writeonly buffer New { uint dst[]; };
uniform uint count;
uniform uint entries;
uniform uint components;  // uints per element: 3 for a vec3 or a triangle, 1 for a colour

void main() {
  uint j = elementIndex();
  if (j >= count) return;
  uvec4 e = table[owner(j, entries)];
  uint l = j - e.x;
  for (uint c = 0u; c < components; ++c) {
    dst[components * j + c] = l < e.z ? old[components * (e.y + l) + c]
                                      : delta[components * (e.w + l - e.z) + c];
  }
}
)";

// One array's two copies and its staging buffer for the Δ.
struct Stream {
  std::array<GLuint, 2> copies{};
  GLuint delta = 0;
  GLuint components = 0;  // uint32 per element
  std::vector<std::uint32_t> staged;

  void create(std::uint64_t elements, GLuint uintsPerElement) {
    components = uintsPerElement;
    for (GLuint& b : copies) b = makeBuffer(elements * 4 * uintsPerElement);
    delta = makeBuffer(elements * 4 * uintsPerElement);
  }
  void destroy() {
    for (GLuint b : {copies[0], copies[1], delta}) {
      if (b) glDeleteBuffers(1, &b);
    }
  }
};

}  // namespace

struct GpuStream::State {
  const Package* package = nullptr;
  StreamCapacity capacity;
  bool normals = false, colors = false, uvs = false;
  Program program;
  Stream positions, normalStream, colorStream, uvStream, source;
  GLuint vertexTable = 0, triangleTable = 0;
  int current = 0;  // which copy holds the frame
  std::vector<std::uint64_t> vertexStart, triangleStart, oldVertexStart, oldTriangleStart;
  std::vector<std::uint32_t> vertexCounts, triangleCounts;
  std::vector<std::array<std::uint32_t, 4>> vertexRows, triangleRows;

  // Object i's rows: the prefix both selections share stays on the GPU, the rest is staged from
  // the package.
  void stageVertices(std::size_t i, std::uint32_t count, std::uint64_t& delta,
                     std::uint64_t& keptTotal);
  void stageTriangles(std::size_t i, std::uint32_t count, std::uint64_t& delta,
                      std::uint64_t& keptTotal);
  // The staged data and the kept prefixes into the next copy, on the GPU.
  void assembleFrame(std::uint64_t vertices, std::uint64_t triangles);

  ~State() {
    for (Stream* s : {&positions, &normalStream, &colorStream, &uvStream, &source}) s->destroy();
    for (GLuint b : {vertexTable, triangleTable}) {
      if (b) glDeleteBuffers(1, &b);
    }
  }

  void assemble(Stream& s, std::uint64_t count, GLuint table, std::size_t entries) {
    if (count == 0) return;
    glNamedBufferSubData(s.delta, 0, static_cast<GLsizeiptr>(s.staged.size() * 4), s.staged.data());
    const GLuint p = program.id();
    glUniform1ui(glGetUniformLocation(p, "count"), static_cast<GLuint>(count));
    glUniform1ui(glGetUniformLocation(p, "entries"), static_cast<GLuint>(entries));
    glUniform1ui(glGetUniformLocation(p, "components"), s.components);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, s.copies[static_cast<std::size_t>(current)]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, s.delta);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, table);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, s.copies[static_cast<std::size_t>(1 - current)]);
    dispatchElements(count);
  }
};

namespace {

void stage(std::vector<std::uint32_t>& to, const void* from, std::size_t bytes) {
  const std::size_t at = to.size();
  to.resize(at + bytes / 4);
  std::memcpy(to.data() + at, from, bytes);
}

}  // namespace

void GpuStream::State::stageVertices(std::size_t i, std::uint32_t count, std::uint64_t& delta,
                                     std::uint64_t& keptTotal) {
  const std::uint32_t kept = std::min(count, vertexCounts[i]);
  vertexRows.push_back({static_cast<std::uint32_t>(vertexStart[i]),
                        static_cast<std::uint32_t>(oldVertexStart.empty() ? 0 : oldVertexStart[i]),
                        kept, static_cast<std::uint32_t>(delta)});
  const std::size_t fresh = count - kept;
  stage(positions.staged, package->positions(i).data() + kept, fresh * sizeof(Vec3f));
  if (normals) stage(normalStream.staged, package->normals(i).data() + kept, fresh * sizeof(Vec3f));
  if (colors) stage(colorStream.staged, package->colors(i).data() + kept, fresh * sizeof(Rgba8));
  if (uvs) stage(uvStream.staged, package->uvs(i).data() + kept, fresh * sizeof(Vec2f));
  delta += fresh;
  keptTotal += kept;
}

void GpuStream::State::stageTriangles(std::size_t i, std::uint32_t count, std::uint64_t& delta,
                                      std::uint64_t& keptTotal) {
  const std::uint32_t kept = std::min(count, triangleCounts[i]);
  triangleRows.push_back(
      {static_cast<std::uint32_t>(triangleStart[i]),
       static_cast<std::uint32_t>(oldTriangleStart.empty() ? 0 : oldTriangleStart[i]), kept,
       static_cast<std::uint32_t>(delta)});
  const std::size_t fresh = count - kept;
  stage(source.staged, package->triangles(i).data() + 3 * std::size_t{kept},
        fresh * 3 * sizeof(std::uint32_t));
  delta += fresh;
  keptTotal += kept;
}

void GpuStream::State::assembleFrame(std::uint64_t vertices, std::uint64_t triangles) {
  glNamedBufferSubData(vertexTable, 0, static_cast<GLsizeiptr>(vertexRows.size() * 16),
                       vertexRows.data());
  glNamedBufferSubData(triangleTable, 0, static_cast<GLsizeiptr>(triangleRows.size() * 16),
                       triangleRows.data());
  glUseProgram(program.id());
  assemble(positions, vertices, vertexTable, vertexRows.size());
  if (normals) assemble(normalStream, vertices, vertexTable, vertexRows.size());
  if (colors) assemble(colorStream, vertices, vertexTable, vertexRows.size());
  if (uvs) assemble(uvStream, vertices, vertexTable, vertexRows.size());
  assemble(source, triangles, triangleTable, triangleRows.size());
  // Draws read the vertices; the reformation reads the source triangles.
  glMemoryBarrier(GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT |
                  GL_BUFFER_UPDATE_BARRIER_BIT);
}

Result<GpuStream> GpuStream::create(const Package& package, const StreamCapacity& capacity) {
  if (capacity.vertices >= (std::uint64_t{1} << 30) ||
      capacity.triangles >= (std::uint64_t{1} << 30))
    return Error{
        ErrorKind::kUnsupported,
        "GPU streaming addresses elements with 32-bit offsets: capacity over 1 G elements"};
  auto s = std::make_unique<State>();
  s->package = &package;
  s->capacity = capacity;
  s->normals = package.header().hasNormals();
  s->colors = package.header().hasColors();
  s->uvs = package.header().hasUvs();
  auto program = Program::link({{GL_COMPUTE_SHADER, std::string(kElementGlsl) + kAssembleMain}});
  if (!program) return program.status();
  s->program = std::move(*program);
  s->positions.create(capacity.vertices, 3);
  if (s->normals) s->normalStream.create(capacity.vertices, 3);
  if (s->colors) s->colorStream.create(capacity.vertices, 1);
  if (s->uvs) s->uvStream.create(capacity.vertices, 2);
  s->source.create(capacity.triangles, 3);
  const std::size_t objects = package.objectCount();
  s->vertexTable = makeBuffer(objects * 16);
  s->triangleTable = makeBuffer(objects * 16);
  s->vertexStart.assign(objects + 1, 0);
  s->triangleStart.assign(objects + 1, 0);
  s->vertexCounts.assign(objects, 0);
  s->triangleCounts.assign(objects, 0);
  return GpuStream(std::move(s));
}

GpuStream::GpuStream(std::unique_ptr<State> state) : state_(std::move(state)) {}
GpuStream::GpuStream(GpuStream&&) noexcept = default;
GpuStream& GpuStream::operator=(GpuStream&&) noexcept = default;
GpuStream::~GpuStream() = default;

Result<FrameStats> GpuStream::update(std::span<const std::uint32_t> vc,
                                     std::span<const std::uint32_t> tc) {
  State& s = *state_;
  const Package& package = *s.package;
  const std::size_t objects = package.objectCount();
  assert(vc.size() == objects && tc.size() == objects);
  const auto start = std::chrono::steady_clock::now();
  std::uint64_t vertices = 0, triangles = 0;
  for (std::size_t i = 0; i < objects; ++i) {
    vertices += vc[i];
    triangles += tc[i];
  }
  if (vertices > s.capacity.vertices || triangles > s.capacity.triangles)
    return Error{ErrorKind::kLimit,
                 fmt::format("selection of {} vertices and {} triangles exceeds the GPU stream's "
                             "capacity of {} and {}",
                             vertices, triangles, s.capacity.vertices, s.capacity.triangles)};
  // An unchanged selection costs nothing: the current copy already holds it.
  if (std::equal(vc.begin(), vc.end(), s.vertexCounts.begin()) &&
      std::equal(tc.begin(), tc.end(), s.triangleCounts.begin()))
    return FrameStats{};
  std::swap(s.oldVertexStart, s.vertexStart);
  std::swap(s.oldTriangleStart, s.triangleStart);
  s.vertexStart.assign(objects + 1, 0);
  s.triangleStart.assign(objects + 1, 0);
  for (Stream* stream : {&s.positions, &s.normalStream, &s.colorStream, &s.uvStream, &s.source})
    stream->staged.clear();
  s.vertexRows.clear();
  s.triangleRows.clear();
  FrameStats stats;
  std::uint64_t vertexDelta = 0, triangleDelta = 0, keptVertices = 0, keptTriangles = 0;
  for (std::size_t i = 0; i < objects; ++i) {
    s.vertexStart[i + 1] = s.vertexStart[i] + vc[i];
    s.triangleStart[i + 1] = s.triangleStart[i] + tc[i];
    if (vc[i] != s.vertexCounts[i]) ++stats.objectsChanged;
    if (vc[i] > 0) s.stageVertices(i, vc[i], vertexDelta, keptVertices);
    if (tc[i] > 0) s.stageTriangles(i, tc[i], triangleDelta, keptTriangles);
  }
  s.assembleFrame(vertices, triangles);
  s.current = 1 - s.current;
  s.vertexCounts.assign(vc.begin(), vc.end());
  s.triangleCounts.assign(tc.begin(), tc.end());

  const std::uint64_t vertexBytes = StreamCapacity::vertexBytes(package);
  stats.verticesRead = vertexDelta;
  stats.trianglesRead = triangleDelta;
  stats.bytesRead = vertexDelta * vertexBytes + triangleDelta * 12;
  stats.bytesMoved = keptVertices * vertexBytes + keptTriangles * 12;
  stats.reassemblyMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

const Package& GpuStream::package() const {
  return *state_->package;
}
const StreamCapacity& GpuStream::capacity() const {
  return state_->capacity;
}
std::uint64_t GpuStream::vertexCount() const {
  return state_->vertexStart.back();
}
std::uint64_t GpuStream::triangleCount() const {
  return state_->triangleStart.back();
}
std::span<const std::uint64_t> GpuStream::vertexStart() const {
  return state_->vertexStart;
}
std::span<const std::uint64_t> GpuStream::triangleStart() const {
  return state_->triangleStart;
}
std::span<const std::uint32_t> GpuStream::vertexCounts() const {
  return state_->vertexCounts;
}
std::span<const std::uint32_t> GpuStream::triangleCounts() const {
  return state_->triangleCounts;
}
unsigned GpuStream::positionBuffer() const {
  return state_->positions.copies[static_cast<std::size_t>(state_->current)];
}
unsigned GpuStream::normalBuffer() const {
  return state_->normals ? state_->normalStream.copies[static_cast<std::size_t>(state_->current)]
                         : 0;
}
unsigned GpuStream::uvBuffer() const {
  return state_->uvs ? state_->uvStream.copies[static_cast<std::size_t>(state_->current)] : 0;
}
unsigned GpuStream::colorBuffer() const {
  return state_->colors ? state_->colorStream.copies[static_cast<std::size_t>(state_->current)] : 0;
}
unsigned GpuStream::sourceBuffer() const {
  return state_->source.copies[static_cast<std::size_t>(state_->current)];
}

}  // namespace lodforge
