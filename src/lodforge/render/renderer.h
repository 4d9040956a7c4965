// Draws the streamed buffer (runtime/stream.h) with OpenGL 4.5: one vertex and one index buffer
// sized to the stream's arena, one multi-draw per frame whose commands are the objects'
// triangle ranges (each command's base instance is the object id, so per-object colour and LOD
// ratio reach the shaders as instanced attributes), headlight shading. A textured package is
// drawn one multi-draw per image, with its texture (render/textures.h). Offscreen rendering goes
// into a Framebuffer and reads back as an Image.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "lodforge/core/status.h"
#include "lodforge/render/gpu_stream.h"
#include "lodforge/render/image.h"
#include "lodforge/runtime/camera.h"
#include "lodforge/runtime/stream.h"
#include "lodforge/simplify/package.h"

namespace lodforge {

enum class ColorMode : std::uint8_t {
  kShaded,    // vertex colours when the package has them, else each object's base colour
  kObject,    // a distinct colour per object
  kLodRatio,  // vc / p: blue (coarsest) to red (full detail)
  kNormal,    // the normal as a colour
};

// "shaded", "object", "lod", "normal".
Result<ColorMode> parseColorMode(std::string_view text);
const char* colorModeName(ColorMode mode);

// Draw into the window again (after offscreen work).
void bindWindowFramebuffer();
// The pixels of a framebuffer (0: the window's back buffer), RGBA8, top row first.
Image readPixels(unsigned framebuffer, std::uint32_t width, std::uint32_t height);

// An offscreen colour + depth target.
class Framebuffer {
 public:
  static Result<Framebuffer> create(std::uint32_t width, std::uint32_t height);
  Framebuffer(Framebuffer&&) noexcept;
  Framebuffer& operator=(Framebuffer&&) noexcept;
  ~Framebuffer();

  void bind() const;
  Image read() const;  // RGBA8, top row first
  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }

 private:
  Framebuffer() = default;
  std::uint32_t width_ = 0, height_ = 0;
  unsigned framebuffer_ = 0, color_ = 0, depth_ = 0;
};

struct DrawOptions {
  ColorMode colorMode = ColorMode::kShaded;
  // Dark slate: white and light grey parts (common CAD base colours) stay visible.
  std::array<std::uint8_t, 3> background = {40, 44, 52};
};

class Renderer {
 public:
  // Needs a current GL 4.5 context. Buffers hold a StreamBuffer's arena for `capacity`.
  // Without `vertexBuffers` only the index buffer is made: the renderer then draws from a
  // GpuStream's buffers (attach) and upload() may not be used.
  static Result<Renderer> create(const Package& package, const StreamCapacity& capacity,
                                 bool vertexBuffers = true);
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  ~Renderer();

  // Makes the GL buffers hold the stream's current contents and draw commands. With
  // `indices` false the index buffer is left alone (GpuReformer writes it).
  void upload(const StreamBuffer& buffer, bool indices = true);
  // Draws from a GPU stream's buffers instead (nothing is copied; the indices come from
  // GpuReformer::reform(stream, indexBuffer())).
  void attach(const GpuStream& stream);
  // Draws into the bound framebuffer (viewport = camera's size).
  void draw(const Camera& camera, const DrawOptions& options) const;
  std::uint64_t uploadedBytes() const;  // by the last upload
  // The GL buffer holding the indices (for the compute-shader reformation).
  unsigned indexBuffer() const;

  struct State;  // (its helpers in renderer.cpp take it)

 private:
  explicit Renderer(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
  void setCommands(std::span<const std::uint32_t> counts,
                   std::span<const std::uint32_t> triangleCounts,
                   std::span<const std::uint64_t> triangleStart);
};

// Column-major 4x4 view-projection of a camera (OpenGL clip space), in float.
void viewProjectionMatrix(const Camera& camera, float out[16]);

// The GL state every draw starts from: the camera's viewport, a depth test that keeps the
// nearest, and the target cleared to `background`.
void beginFrame(const Camera& camera, const std::array<std::uint8_t, 3>& background);
// Uses `program` with the camera's "viewProjection" matrix and "eye" position set.
void useCameraProgram(unsigned program, const Camera& camera);

}  // namespace lodforge
