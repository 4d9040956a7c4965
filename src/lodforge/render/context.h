// OpenGL 4.5 core contexts: EGL surfaceless for headless work (Mesa's llvmpipe provides 4.5
// without a GPU, CI included) and a GLFW window for the viewer. GL calls go through libepoxy.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "lodforge/core/status.h"

struct GLFWwindow;

namespace lodforge {

class GlContext {
 public:
  // Offscreen: draw into a Framebuffer (renderer.h).
  static Result<std::unique_ptr<GlContext>> headless();
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
  GLFWwindow* glfwWindow() const;  // null when headless

 private:
  struct State;
  explicit GlContext(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

// Whether a window could open: an X11 or Wayland display is set.
bool displayAvailable();

}  // namespace lodforge
