#include "lodforge/render/context.h"

#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace lodforge {

struct GlContext::State {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  GLFWwindow* window = nullptr;
  const char* platform = "GLFW window";
};

namespace {

Error eglError(const char* what) {
  return Error{ErrorKind::kUnsupported, fmt::format("{} failed (EGL error 0x{:x})", what,
                                                    static_cast<unsigned>(eglGetError()))};
}

Status requireVersion45() {
  const int version = epoxy_gl_version();
  if (version < 45)
    return Error{ErrorKind::kUnsupported,
                 fmt::format("OpenGL 4.5 core is needed; the context offers {}.{}", version / 10,
                             version % 10)};
  return {};
}

}  // namespace

GlContext::GlContext(std::unique_ptr<State> state) : state_(std::move(state)) {}

GlContext::~GlContext() {
  // Neither glfwTerminate nor eglTerminate: both unload the GL driver, and Mesa's few
  // process-lifetime allocations would then show as leaks from an unknown module; the display
  // connection is the process's until exit anyway.
  if (state_->window) glfwDestroyWindow(state_->window);
  if (state_->context != EGL_NO_CONTEXT) {
    eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(state_->display, state_->context);
  }
}

namespace {

// A display to try, and its platform's name.
struct Candidate {
  EGLDisplay display;
  const char* platform;
};

// Mesa's surfaceless platform: no window system at all; rendering goes to framebuffer objects.
// The EXT entry points: libepoxy resolves them from the client extensions, before any display
// exists to tell the EGL version.
void addSurfaceless(std::vector<Candidate>& out, std::vector<std::string>& why) {
  if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless")) {
    why.push_back("EGL lacks EGL_MESA_platform_surfaceless");
    return;
  }
  EGLDisplay display =
      eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) {
    why.push_back("surfaceless: " + eglError("eglGetPlatformDisplay").message);
    return;
  }
  out.push_back({display, "EGL surfaceless"});
}

// Every EGL device: NVIDIA's driver renders without a display through one, and Mesa offers its
// software device too.
void addDevices(std::vector<Candidate>& out, std::vector<std::string>& why) {
  for (const char* extension : {"EGL_EXT_platform_device", "EGL_EXT_device_enumeration"}) {
    if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, extension)) {
      why.push_back(fmt::format("EGL lacks {}", extension));
      return;
    }
  }
  constexpr EGLint kMaxDevices = 16;
  EGLDeviceEXT devices[kMaxDevices];
  EGLint count = 0;
  if (!eglQueryDevicesEXT(kMaxDevices, devices, &count)) {
    why.push_back(eglError("eglQueryDevicesEXT").message);
    return;
  }
  if (count == 0) why.push_back("no EGL device");
  for (EGLint i = 0; i < count; ++i) {
    EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (display == EGL_NO_DISPLAY) {
      why.push_back(fmt::format("device {}: {}", i, eglError("eglGetPlatformDisplay").message));
      continue;
    }
    out.push_back({display, "EGL device"});
  }
}

// An OpenGL 4.5 core context current on `display`, or why not; a context that fails after its
// creation is destroyed.
Result<EGLContext> currentContext(EGLDisplay display) {
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) return eglError("eglInitialize");
  if (!eglBindAPI(EGL_OPENGL_API)) return eglError("eglBindAPI(OpenGL)");
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                               4,
                               EGL_CONTEXT_MINOR_VERSION,
                               5,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                               EGL_NONE};
  EGLContext context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (context == EGL_NO_CONTEXT) return eglError("eglCreateContext(OpenGL 4.5 core)");
  Status made = eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)
                    ? requireVersion45()
                    : Status(eglError("eglMakeCurrent"));
  if (made.ok()) return context;
  eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display, context);
  return made.error();
}

}  // namespace

// Each candidate in turn, to the first that gives a 4.5 core context: surfaceless first (Mesa,
// machines without a GPU), then the EGL devices.
Result<std::unique_ptr<GlContext>> GlContext::headless(EglPlatform platform) {
  std::vector<Candidate> candidates;
  std::vector<std::string> why;
  if (platform != EglPlatform::kDevice) addSurfaceless(candidates, why);
  if (platform != EglPlatform::kSurfaceless) addDevices(candidates, why);
  for (const Candidate& c : candidates) {
    Result<EGLContext> context = currentContext(c.display);
    if (!context) {
      why.push_back(fmt::format("{}: {}", c.platform, context.error().message));
      continue;
    }
    auto state = std::make_unique<State>();
    state->display = c.display;
    state->context = *context;
    state->platform = c.platform;
    return std::unique_ptr<GlContext>(new GlContext(std::move(state)));
  }
  return Error{ErrorKind::kUnsupported,
               fmt::format("headless OpenGL 4.5: no EGL platform gave a context ({}); Mesa's "
                           "libegl1 and libgl1-mesa-dri provide one (scripts/install-deps.sh)",
                           fmt::join(why, "; "))};
}

Result<std::unique_ptr<GlContext>> GlContext::window(std::uint32_t width, std::uint32_t height,
                                                     const std::string& title) {
  if (!displayAvailable())
    return Error{ErrorKind::kUnsupported,
                 "no display (DISPLAY and WAYLAND_DISPLAY are unset): a window cannot open; "
                 "`lodforge render` draws the same frames headless into PNG files"};
  if (!glfwInit()) return Error{ErrorKind::kUnsupported, "GLFW could not initialise the display"};
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  auto state = std::make_unique<State>();
  state->window = glfwCreateWindow(static_cast<int>(width), static_cast<int>(height), title.c_str(),
                                   nullptr, nullptr);
  if (state->window == nullptr) {
    glfwTerminate();
    return Error{ErrorKind::kUnsupported, "GLFW could not open an OpenGL 4.5 core window"};
  }
  glfwMakeContextCurrent(state->window);
  glfwSwapInterval(1);
  auto context = std::unique_ptr<GlContext>(new GlContext(std::move(state)));
  LODFORGE_TRY(requireVersion45());
  return context;
}

void GlContext::makeCurrent() {
  if (state_->window) {
    glfwMakeContextCurrent(state_->window);
  } else {
    eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, state_->context);
  }
}

void GlContext::finish() {
  glFinish();
}

std::string GlContext::renderer() const {
  const auto* text = glGetString(GL_RENDERER);
  return text ? reinterpret_cast<const char*>(text) : "";
}

std::string GlContext::platform() const {
  return state_->platform;
}

std::string GlContext::version() const {
  const auto* text = glGetString(GL_VERSION);
  return text ? reinterpret_cast<const char*>(text) : "";
}

GLFWwindow* GlContext::glfwWindow() const {
  return state_->window;
}

bool displayAvailable() {
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (x11 && *x11) || (wayland && *wayland);
}

}  // namespace lodforge
