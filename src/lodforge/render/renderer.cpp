#include "lodforge/render/renderer.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <vector>

#include <epoxy/gl.h>

#include "lodforge/render/shader.h"
#include "lodforge/render/textures.h"

namespace lodforge {

Result<ColorMode> parseColorMode(std::string_view text) {
  if (text == "shaded") return ColorMode::kShaded;
  if (text == "object") return ColorMode::kObject;
  if (text == "lod") return ColorMode::kLodRatio;
  if (text == "normal") return ColorMode::kNormal;
  return Error{ErrorKind::kUsage,
               fmt::format("colour mode '{}': expected shaded, object, lod or normal", text)};
}

const char* colorModeName(ColorMode mode) {
  switch (mode) {
    case ColorMode::kShaded:
      return "shaded";
    case ColorMode::kObject:
      return "object";
    case ColorMode::kLodRatio:
      return "lod";
    case ColorMode::kNormal:
      return "normal";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------------
// Framebuffer

Result<Framebuffer> Framebuffer::create(std::uint32_t width, std::uint32_t height) {
  Framebuffer f;
  f.width_ = width;
  f.height_ = height;
  glCreateRenderbuffers(1, &f.color_);
  glNamedRenderbufferStorage(f.color_, GL_RGBA8, static_cast<GLsizei>(width),
                             static_cast<GLsizei>(height));
  glCreateRenderbuffers(1, &f.depth_);
  glNamedRenderbufferStorage(f.depth_, GL_DEPTH_COMPONENT24, static_cast<GLsizei>(width),
                             static_cast<GLsizei>(height));
  glCreateFramebuffers(1, &f.framebuffer_);
  glNamedFramebufferRenderbuffer(f.framebuffer_, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, f.color_);
  glNamedFramebufferRenderbuffer(f.framebuffer_, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, f.depth_);
  if (glCheckNamedFramebufferStatus(f.framebuffer_, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    return Error{ErrorKind::kUnsupported,
                 fmt::format("cannot create a {}x{} framebuffer", width, height)};
  return f;
}

Framebuffer::Framebuffer(Framebuffer&& o) noexcept {
  *this = std::move(o);
}

Framebuffer& Framebuffer::operator=(Framebuffer&& o) noexcept {
  std::swap(width_, o.width_);
  std::swap(height_, o.height_);
  std::swap(framebuffer_, o.framebuffer_);
  std::swap(color_, o.color_);
  std::swap(depth_, o.depth_);
  return *this;
}

Framebuffer::~Framebuffer() {
  if (framebuffer_) glDeleteFramebuffers(1, &framebuffer_);
  if (color_) glDeleteRenderbuffers(1, &color_);
  if (depth_) glDeleteRenderbuffers(1, &depth_);
}

void Framebuffer::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
}

Image Framebuffer::read() const {
  return readPixels(framebuffer_, width_, height_);
}

void bindWindowFramebuffer() {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

Image readPixels(unsigned framebuffer, std::uint32_t width, std::uint32_t height) {
  Image image(width, height);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  if (framebuffer == 0) glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, static_cast<GLsizei>(width), static_cast<GLsizei>(height), GL_RGBA,
               GL_UNSIGNED_BYTE, image.rgba.data());
  // GL's rows start at the bottom; images start at the top.
  const std::size_t row = std::size_t{width} * 4;
  std::vector<std::uint8_t> swap(row);
  for (std::uint32_t y = 0; y < height / 2; ++y) {
    std::uint8_t* a = image.rgba.data() + y * row;
    std::uint8_t* b = image.rgba.data() + (height - 1 - y) * row;
    std::memcpy(swap.data(), a, row);
    std::memcpy(a, b, row);
    std::memcpy(b, swap.data(), row);
  }
  return image;
}

// ---------------------------------------------------------------------------------------------
// Renderer

namespace {

constexpr const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec4 color;
layout(location = 3) in vec4 objectColor;  // per object (instanced)
layout(location = 4) in float lodRatio;    // per object (instanced)
layout(location = 5) in vec2 uv;
uniform mat4 viewProjection;
uniform int mode;
uniform bool useVertexColor;
out vec3 worldPosition;
out vec3 worldNormal;
out vec4 baseColor;
out vec2 texcoord;

vec3 ramp(float t) {  // blue, cyan, green, yellow, red
  return clamp(vec3(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)),
               0.0, 1.0);
}

void main() {
  gl_Position = viewProjection * vec4(position, 1.0);
  worldPosition = position;
  worldNormal = normal;
  texcoord = uv;
  if (mode == 0) baseColor = useVertexColor ? color : objectColor;
  else if (mode == 1) baseColor = objectColor;
  else baseColor = vec4(ramp(lodRatio), 1.0);
}
)";

constexpr const char* kFragmentShader = R"(#version 450 core
in vec3 worldPosition;
in vec3 worldNormal;
in vec4 baseColor;
in vec2 texcoord;
uniform vec3 eye;
uniform int mode;
uniform bool useVertexNormal;
uniform bool useTexture;
uniform sampler2D baseTexture;
out vec4 fragColor;

void main() {
  // Without stored normals, the face normal from screen-space derivatives (flat shading).
  vec3 n = useVertexNormal ? normalize(worldNormal)
                           : normalize(cross(dFdx(worldPosition), dFdy(worldPosition)));
  if (mode == 3) {
    fragColor = vec4(0.5 * n + 0.5, 1.0);
    return;
  }
  // A headlight, two-sided: CAD parts are often open shells.
  float diffuse = abs(dot(n, normalize(eye - worldPosition)));
  // As glTF: the texel times the vertex colour (baseColor is the vertex or object colour).
  vec3 albedo = useTexture ? texture(baseTexture, texcoord).rgb * baseColor.rgb : baseColor.rgb;
  fragColor = vec4(albedo * (0.3 + 0.7 * diffuse), 1.0);
}
)";

// A distinct, stable colour per object id: golden-ratio hue steps, HSV (s 0.65, v 0.9) to RGB.
Rgba8 objectIdColor(std::size_t id) {
  const double hue = std::fmod(static_cast<double>(id) * 0.6180339887498949, 1.0) * 6.0;
  const double s = 0.65, v = 0.9;
  const auto channel = [&](double n) {
    const double k = std::fmod(n + hue, 6.0);
    const double c = v - v * s * std::clamp(std::min(k, 4.0 - k), 0.0, 1.0);
    return static_cast<std::uint8_t>(std::lround(c * 255));
  };
  return {channel(5), channel(3), channel(1), 255};
}

struct DrawCommand {  // GL's DrawElementsIndirectCommand
  GLuint count, instanceCount, firstIndex;
  GLint baseVertex;
  GLuint baseInstance;
};

}  // namespace

struct Renderer::State {
  const Package* package = nullptr;
  StreamCapacity capacity;
  bool normals = false, colors = false, uvs = false;
  Program program;
  GLuint vertexArray = 0;
  GLuint positions = 0, normalBuffer = 0, colorBuffer = 0, uvBuffer = 0, indices = 0;
  PackageTextures textures;
  // Textured: the commands sorted by image, drawn one image at a time.
  struct ImageRange {
    std::uint32_t image;
    GLsizei first, count;
  };
  std::vector<ImageRange> imageRanges;
  GLuint objectColors = 0, lodRatios = 0, commands = 0;
  GLsizei commandCount = 0;
  std::vector<DrawCommand> commandList;
  std::vector<Rgba8> baseColors, idColors;
  std::vector<float> ratios;
  std::uint64_t uploaded = 0;
  bool attached = false;  // drawing from a GpuStream's buffers
  // What the buffers hold: a stream's update (StreamBuffer::lastUpdate) and whether its indices
  // came with it. 0 when unknown (never uploaded, or a GPU stream wrote the indices).
  std::uint64_t heldUpdate = 0;
  bool heldIndices = false;
  std::vector<StreamBuffer::Range> vertexRanges, triangleRanges;
  mutable bool idColorsUploaded = false;  // which colours the object colour buffer holds

  ~State() {
    const GLuint buffers[] = {positions, normalBuffer, colorBuffer, uvBuffer,
                              indices,   objectColors, lodRatios,   commands};
    for (GLuint b : buffers) {
      if (b) glDeleteBuffers(1, &b);
    }
    if (vertexArray) glDeleteVertexArrays(1, &vertexArray);
  }
};

Result<Renderer> Renderer::create(const Package& package, const StreamCapacity& capacity,
                                  bool vertexBuffers) {
  if (!capacity.arenaFitsGpuOffsets())
    return Error{ErrorKind::kUnsupported,
                 "the stream's arena is over 4 G vertex or index offsets: lower the budget or "
                 "--gpu-memory"};
  auto s = std::make_unique<State>();
  s->package = &package;
  s->capacity = capacity;
  s->normals = package.header().hasNormals();
  s->colors = package.header().hasColors();
  s->uvs = package.header().hasUvs();
  Result<PackageTextures> textures = PackageTextures::load(package);
  if (!textures) return textures.status();
  s->textures = std::move(*textures);
  auto program =
      Program::link({{GL_VERTEX_SHADER, kVertexShader}, {GL_FRAGMENT_SHADER, kFragmentShader}});
  if (!program) return program.status();
  s->program = std::move(*program);

  const std::size_t objects = package.objectCount();
  s->baseColors.resize(objects);
  s->idColors.resize(objects);
  for (std::size_t i = 0; i < objects; ++i) {
    s->baseColors[i] = package.object(i).color;
    s->idColors[i] = objectIdColor(i);
  }
  s->ratios.assign(objects, 1.0f);

  if (vertexBuffers) {
    const std::uint64_t vertices = capacity.arenaVertices();  // a StreamBuffer's slots
    s->positions = makeBuffer(vertices * sizeof(Vec3f));
    if (s->normals) s->normalBuffer = makeBuffer(vertices * sizeof(Vec3f));
    if (s->colors) s->colorBuffer = makeBuffer(vertices * sizeof(Rgba8));
    if (s->uvs) s->uvBuffer = makeBuffer(vertices * sizeof(Vec2f));
  }
  // A GpuStream is compact; a StreamBuffer's slots spread over its arena.
  const std::uint64_t triangles = vertexBuffers ? capacity.arenaTriangles() : capacity.triangles;
  s->indices = makeBuffer(triangles * 3 * sizeof(std::uint32_t));
  s->objectColors = makeBuffer(objects * sizeof(Rgba8), s->baseColors.data());
  s->lodRatios = makeBuffer(objects * sizeof(float), s->ratios.data());
  s->commands = makeBuffer(objects * sizeof(DrawCommand));

  GLuint& vao = s->vertexArray;
  glCreateVertexArrays(1, &vao);
  const auto attribute = [&](GLuint location, GLuint buffer, GLint size, GLenum type,
                             GLboolean normalized, GLsizei stride, GLuint divisor) {
    glEnableVertexArrayAttrib(vao, location);
    glVertexArrayVertexBuffer(vao, location, buffer, 0, stride);
    glVertexArrayAttribFormat(vao, location, size, type, normalized, 0);
    glVertexArrayAttribBinding(vao, location, location);
    glVertexArrayBindingDivisor(vao, location, divisor);
  };
  attribute(0, s->positions, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3f), 0);
  if (s->normals) attribute(1, s->normalBuffer, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3f), 0);
  if (s->colors) attribute(2, s->colorBuffer, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(Rgba8), 0);
  attribute(3, s->objectColors, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(Rgba8), 1);
  attribute(4, s->lodRatios, 1, GL_FLOAT, GL_FALSE, sizeof(float), 1);
  if (s->uvs) attribute(5, s->uvBuffer, 2, GL_FLOAT, GL_FALSE, sizeof(Vec2f), 0);
  glVertexArrayElementBuffer(vao, s->indices);
  return Renderer(std::move(s));
}

Renderer::Renderer(std::unique_ptr<State> state) : state_(std::move(state)) {}
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;
Renderer::~Renderer() = default;

// The whole used arena when the buffers do not hold the frame before; else only what the last
// update wrote (on a real GPU the copy across the bus is most of the frame: 1 GB at 18 M).
void Renderer::upload(const StreamBuffer& buffer, bool indices) {
  State& s = *state_;
  assert(s.positions != 0 && "created without vertex buffers: attach a GpuStream instead");
  // Indices the GPU reformer wrote are not the stream's: then everything goes again.
  buffer.rangesSince(s.heldIndices == indices ? s.heldUpdate : 0, StreamBuffer::kUploadRanges,
                     s.vertexRanges, s.triangleRanges);
  const auto vertexArray = [&](GLuint target, auto array) {
    return uploadRanges(target, std::as_bytes(array), sizeof(array[0]), s.vertexRanges);
  };
  s.uploaded = vertexArray(s.positions, buffer.positions());
  if (s.normals) s.uploaded += vertexArray(s.normalBuffer, buffer.normals());
  if (s.colors) s.uploaded += vertexArray(s.colorBuffer, buffer.colors());
  if (s.uvs) s.uploaded += vertexArray(s.uvBuffer, buffer.uvs());
  if (indices)
    s.uploaded += uploadRanges(s.indices, std::as_bytes(buffer.indices()),
                               3 * sizeof(std::uint32_t), s.triangleRanges);
  s.heldUpdate = buffer.lastUpdate();
  s.heldIndices = indices;

  setCommands(buffer.vertexCounts(), buffer.triangleCounts(), buffer.triangleStart());
  if (s.attached) {
    // Back to the renderer's own buffers after drawing from a GPU stream.
    glVertexArrayVertexBuffer(s.vertexArray, 0, s.positions, 0, sizeof(Vec3f));
    if (s.normals) glVertexArrayVertexBuffer(s.vertexArray, 1, s.normalBuffer, 0, sizeof(Vec3f));
    if (s.colors) glVertexArrayVertexBuffer(s.vertexArray, 2, s.colorBuffer, 0, sizeof(Rgba8));
    if (s.uvs) glVertexArrayVertexBuffer(s.vertexArray, 5, s.uvBuffer, 0, sizeof(Vec2f));
    s.attached = false;
  }
}

void Renderer::attach(const GpuStream& stream) {
  State& s = *state_;
  s.uploaded = 0;
  s.heldUpdate = 0;  // the GPU stream's reformer writes the index buffer
  glVertexArrayVertexBuffer(s.vertexArray, 0, stream.positionBuffer(), 0, sizeof(Vec3f));
  if (s.normals)
    glVertexArrayVertexBuffer(s.vertexArray, 1, stream.normalBuffer(), 0, sizeof(Vec3f));
  if (s.colors) glVertexArrayVertexBuffer(s.vertexArray, 2, stream.colorBuffer(), 0, sizeof(Rgba8));
  if (s.uvs) glVertexArrayVertexBuffer(s.vertexArray, 5, stream.uvBuffer(), 0, sizeof(Vec2f));
  s.attached = true;
  setCommands(stream.vertexCounts(), stream.triangleCounts(), stream.triangleStart());
}

// The commands sorted by their object's image (stable: objects in order within one image),
// with a range per image; nothing to do for a package without textures.
void groupByImage(Renderer::State& s) {
  s.imageRanges.clear();
  if (s.textures.empty()) return;
  std::stable_sort(s.commandList.begin(), s.commandList.end(), [&](const auto& a, const auto& b) {
    return s.textures.objectImage(a.baseInstance) < s.textures.objectImage(b.baseInstance);
  });
  for (std::size_t c = 0; c < s.commandList.size(); ++c) {
    const std::uint32_t image = s.textures.objectImage(s.commandList[c].baseInstance);
    if (s.imageRanges.empty() || s.imageRanges.back().image != image)
      s.imageRanges.push_back({image, static_cast<GLsizei>(c), 0});
    ++s.imageRanges.back().count;
  }
}

// One multi-draw per image, its texture bound (objects without one untextured).
void drawByImage(const Renderer::State& s, GLuint program) {
  glUniform1i(glGetUniformLocation(program, "baseTexture"), 0);
  for (const auto& range : s.imageRanges) {
    const bool has = range.image != kNoImage;
    glUniform1i(glGetUniformLocation(program, "useTexture"), has ? 1 : 0);
    if (has) glBindTextureUnit(0, s.textures.texture(range.image));
    glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT,
                                reinterpret_cast<const void*>(
                                    static_cast<std::uintptr_t>(range.first) * sizeof(DrawCommand)),
                                range.count, 0);
  }
  glBindTextureUnit(0, 0);
}

void Renderer::setCommands(std::span<const std::uint32_t> counts,
                           std::span<const std::uint32_t> triangleCounts,
                           std::span<const std::uint64_t> triangleStart) {
  // One command per object with triangles; its base instance is the object id.
  State& s = *state_;
  s.commandList.clear();
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const std::uint64_t triangles = triangleCounts[i];
    s.ratios[i] = static_cast<float>(counts[i]) /
                  static_cast<float>(std::max<std::uint32_t>(1, s.package->object(i).vertexCount));
    if (triangles == 0) continue;
    s.commandList.push_back({static_cast<GLuint>(3 * triangles), 1,
                             static_cast<GLuint>(3 * triangleStart[i]), 0, static_cast<GLuint>(i)});
  }
  s.commandCount = static_cast<GLsizei>(s.commandList.size());
  groupByImage(s);
  const auto upload = [&](GLuint target, const auto& span) {
    glNamedBufferSubData(target, 0, static_cast<GLsizeiptr>(span.size_bytes()), span.data());
    s.uploaded += span.size_bytes();
  };
  upload(s.commands, std::span<const DrawCommand>(s.commandList));
  upload(s.lodRatios, std::span<const float>(s.ratios));
}

void viewProjectionMatrix(const Camera& camera, float out[16]) {
  // View: x right, y up, looking down -z; projection: GL's symmetric perspective.
  const Vec3d f = camera.forward, u = camera.up, r = camera.right(), e = camera.position;
  const double t = 1.0 / std::tan(camera.fovY / 2), a = camera.aspect();
  const double n = camera.nearPlane, fa = camera.farPlane;
  const double view[4][4] = {{r.x, r.y, r.z, -dot(r, e)},
                             {u.x, u.y, u.z, -dot(u, e)},
                             {-f.x, -f.y, -f.z, dot(f, e)},
                             {0, 0, 0, 1}};
  const double projection[4][4] = {{t / a, 0, 0, 0},
                                   {0, t, 0, 0},
                                   {0, 0, (fa + n) / (n - fa), 2 * fa * n / (n - fa)},
                                   {0, 0, -1, 0}};
  for (int row = 0; row < 4; ++row) {
    for (int column = 0; column < 4; ++column) {
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += projection[row][k] * view[k][column];
      out[column * 4 + row] = static_cast<float>(sum);
    }
  }
}

void beginFrame(const Camera& camera, const std::array<std::uint8_t, 3>& background) {
  glViewport(0, 0, static_cast<GLsizei>(camera.width), static_cast<GLsizei>(camera.height));
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glClearColor(background[0] / 255.0f, background[1] / 255.0f, background[2] / 255.0f, 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

void useCameraProgram(unsigned program, const Camera& camera) {
  float matrix[16];
  viewProjectionMatrix(camera, matrix);
  glUseProgram(program);
  glUniformMatrix4fv(glGetUniformLocation(program, "viewProjection"), 1, GL_FALSE, matrix);
  glUniform3f(glGetUniformLocation(program, "eye"), static_cast<float>(camera.position.x),
              static_cast<float>(camera.position.y), static_cast<float>(camera.position.z));
}

void Renderer::draw(const Camera& camera, const DrawOptions& options) const {
  const State& s = *state_;
  glDisable(GL_CULL_FACE);
  beginFrame(camera, options.background);
  if (s.commandCount == 0) return;

  // Per-object colours: the base colours, or a distinct one per object (re-sent only when the
  // choice changes: 4 bytes per object).
  const bool idColors = options.colorMode == ColorMode::kObject;
  if (idColors != s.idColorsUploaded) {
    const auto& colors = idColors ? s.idColors : s.baseColors;
    glNamedBufferSubData(s.objectColors, 0, static_cast<GLsizeiptr>(colors.size() * sizeof(Rgba8)),
                         colors.data());
    s.idColorsUploaded = idColors;
  }
  // Depth range fitted to the model each frame: the path's planes are chosen for selection
  // (near ~1e-5 of the size) and would waste a 24-bit depth buffer, making coincident faces
  // fight differently from one framebuffer format to the next.
  Camera fitted = camera;
  const auto& h = s.package->header();
  double nearest = 0, farthest = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double e =
        axis == 0 ? camera.position.x : (axis == 1 ? camera.position.y : camera.position.z);
    const double lo = h.boundsMin[axis], hi = h.boundsMax[axis];
    const double inside = std::max({lo - e, 0.0, e - hi});
    nearest += inside * inside;
    const double outside = std::max(std::abs(e - lo), std::abs(e - hi));
    farthest += outside * outside;
  }
  fitted.farPlane = 1.01 * std::sqrt(farthest) + 1e-6;
  fitted.nearPlane =
      std::max({camera.nearPlane, 0.99 * std::sqrt(nearest), fitted.farPlane * 1e-4});
  const GLuint p = s.program.id();
  useCameraProgram(p, fitted);  // fitted.position is camera.position
  glUniform1i(glGetUniformLocation(p, "mode"), static_cast<int>(options.colorMode));
  glUniform1i(glGetUniformLocation(p, "useVertexColor"), s.colors ? 1 : 0);
  glUniform1i(glGetUniformLocation(p, "useVertexNormal"), s.normals ? 1 : 0);
  glBindVertexArray(s.vertexArray);
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, s.commands);
  const bool textured = !s.imageRanges.empty() && options.colorMode == ColorMode::kShaded;
  if (!textured) {
    glUniform1i(glGetUniformLocation(p, "useTexture"), 0);
    glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, nullptr, s.commandCount, 0);
  } else {
    drawByImage(s, p);
  }
  glBindVertexArray(0);
}

std::uint64_t Renderer::uploadedBytes() const {
  return state_->uploaded;
}
unsigned Renderer::indexBuffer() const {
  return state_->indices;
}

}  // namespace lodforge
