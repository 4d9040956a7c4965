// OpenGL 4.5 core contexts: EGL surfaceless or an EGL device for headless work (Mesa's llvmpipe
// provides 4.5 without a GPU, CI included; NVIDIA's driver through the device platform) and a GLFW
// window for the viewer. GL calls go through libepoxy.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "lodforge/core/status.h"

struct GLFWwindow;

namespace lodforge {

// Where a headless context comes from: Mesa's surfaceless platform, an EGL device (NVIDIA's
// driver headless), or the first of them that works.
enum class EglPlatform { kAny, kSurfaceless, kDevice };

class GlContext {
 public:
  // Offscreen: draw into a Framebuffer (renderer.h).
  static Result<std::unique_ptr<GlContext>> headless(EglPlatform platform = EglPlatform::kAny);
  // A window; kUnsupported when there is no display to open it on.
  static Result<std::unique_ptr<GlContext>> window(std::uint32_t width, std::uint32_t height,
                                                   const std::string& title);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  void makeCurrent();
  void finish();                   // glFinish: waits until every command issued so far has run
  std::string renderer() const;    // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version() const;     // GL_VERSION
  std::string platform() const;    // "EGL surfaceless", "EGL device" or "GLFW window"
  GLFWwindow* glfwWindow() const;  // null when headless

 private:
  struct State;
  explicit GlContext(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

// Whether a window could open: an X11 or Wayland display is set.
bool displayAvailable();

}  // namespace lodforge
