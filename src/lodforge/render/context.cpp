#include "lodforge/render/context.h"

#include <cstdlib>
#include <optional>
#include <tuple>
#include <utility>

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
  return Error{ErrorKind::kUnsupported,
               fmt::format("headless OpenGL: {} failed (EGL error 0x{:x}); Mesa's EGL and "
                           "libgl1-mesa-dri provide it (scripts/install-deps.sh)",
                           what, static_cast<unsigned>(eglGetError()))};
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

// Mesa's surfaceless platform: no window system at all; rendering goes to framebuffer objects.
// The EXT entry points: libepoxy resolves them from the client extensions, before any display
// exists to tell the EGL version.
Result<EGLDisplay> surfacelessDisplay() {
  if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless"))
    return Error{ErrorKind::kUnsupported,
                 "headless OpenGL: EGL lacks EGL_MESA_platform_surfaceless (Mesa's libegl1 and "
                 "libgl1-mesa-dri provide it; scripts/install-deps.sh installs them)"};
  EGLDisplay display =
      eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) return eglError("eglGetPlatformDisplay(surfaceless)");
  return display;
}

// The device platform: the first EGL device that initialises. NVIDIA's driver offers this one
// headless, and Mesa offers it too (its software device).
Result<EGLDisplay> deviceDisplay() {
  if (!epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_platform_device") ||
      !epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_EXT_device_enumeration"))
    return Error{ErrorKind::kUnsupported,
                 "headless OpenGL: EGL lacks EGL_EXT_platform_device and "
                 "EGL_MESA_platform_surfaceless"};
  constexpr EGLint kMaxDevices = 16;
  EGLDeviceEXT devices[kMaxDevices];
  EGLint count = 0;
  if (!eglQueryDevicesEXT(kMaxDevices, devices, &count)) return eglError("eglQueryDevicesEXT");
  for (EGLint i = 0; i < count; ++i) {
    EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    EGLint major = 0, minor = 0;
    if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor)) return display;
  }
  return eglError("eglGetPlatformDisplay(device) on every EGL device");
}

// The display and the platform's name. Under kAny a failure names surfaceless's reason, the
// platform expected on machines without a GPU.
Result<std::pair<EGLDisplay, const char*>> platformDisplay(EglPlatform platform) {
  std::optional<Error> first;
  if (platform != EglPlatform::kDevice) {
    auto display = surfacelessDisplay();
    if (display) return std::pair<EGLDisplay, const char*>{*display, "EGL surfaceless"};
    if (platform == EglPlatform::kSurfaceless) return display.error();
    first = display.error();
  }
  auto device = deviceDisplay();
  if (device) return std::pair<EGLDisplay, const char*>{*device, "EGL device"};
  return first ? *first : device.error();
}

}  // namespace

Result<std::unique_ptr<GlContext>> GlContext::headless(EglPlatform platform) {
  auto state = std::make_unique<State>();
  auto display = platformDisplay(platform);
  if (!display) return display.error();
  std::tie(state->display, state->platform) = *display;
  EGLint major = 0, minor = 0;
  if (!eglInitialize(state->display, &major, &minor)) return eglError("eglInitialize");
  if (!eglBindAPI(EGL_OPENGL_API)) return eglError("eglBindAPI(OpenGL)");
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                               4,
                               EGL_CONTEXT_MINOR_VERSION,
                               5,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                               EGL_NONE};
  state->context = eglCreateContext(state->display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
  if (state->context == EGL_NO_CONTEXT) return eglError("eglCreateContext(OpenGL 4.5 core)");
  if (!eglMakeCurrent(state->display, EGL_NO_SURFACE, EGL_NO_SURFACE, state->context))
    return eglError("eglMakeCurrent");
  LODFORGE_TRY(requireVersion45());
  return std::unique_ptr<GlContext>(new GlContext(std::move(state)));
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
