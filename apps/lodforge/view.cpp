// `lodforge view model.lfp`: the budgeted runtime on screen. Each frame selects vertex counts
// under the budget (§4), streams the changed ranges (§3.3), re-forms triangles on the CPU or in
// a compute shader (§3.2) and draws; a Dear ImGui panel sets the budget, the selection and the
// colours and shows what each stage cost. Orbit (drag, wheel) or fly (WASD + drag) camera;
// camera paths record and play in the format of `lodforge bench --path`.
#include <chrono>
#include <cmath>
#include <optional>

#include <fmt/format.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include "cli.h"
#include "cloud.h"
#include "imgui_panel.h"
#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/render/context.h"
#include "lodforge/render/pipeline.h"
#include "lodforge/render/renderer.h"
#include "lodforge/runtime/path.h"
#include "lodforge/runtime/selection.h"
#include "lodforge/runtime/stream.h"
#include "outputs.h"
#include "view_options.h"

namespace lodforge::cli {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct ViewOptions : PathChoice {
  std::string input;
  std::string budget = "10%";
  std::string play;             // orbit, fly or a path file: play it instead of the mouse
  std::string record;           // write the cameras shown here at exit
  std::string screenshot;       // PNG of the last frame
  std::uint64_t stopAfter = 0;  // frames, 0: until the window closes
  std::string color = "shaded";
  bool gpuReform = false;
  bool gpuStream = false;
  bool firstPassOnly = false;
  double minT = 0.65;
};

// Orbit: yaw and pitch around a target at a distance. Fly: the same angles from a position.
struct CameraControl {
  Vec3d target, position;
  double yaw = 0, pitch = 0.3, distance = 1, speed = 1;
  bool fly = false;

  Vec3d forward() const {
    return {std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch)};
  }
  Camera camera(std::uint32_t width, std::uint32_t height, double fovY, const Aabbd& bounds) const {
    const Vec3d eye = fly ? position : target - forward() * distance;
    Camera c = Camera::lookAt(eye, eye + forward(), {0, 0, 1}, fovY, width, height);
    fitClipPlanes(c, bounds);
    return c;
  }
  void follow(const Camera& c) {  // take over a played camera's view
    position = c.position;
    yaw = std::atan2(c.forward.y, c.forward.x);
    pitch = std::asin(std::clamp(c.forward.z, -1.0, 1.0));
    target = c.position + c.forward * distance;
  }
};

struct FrameFigures {
  double selectionMs = 0, generationMs = 0, uploadMs = 0, reformMs = 0, drawMs = 0;
  FrameStats stream;
  std::uint64_t vertices = 0, triangles = 0, objects = 0;
};

// What the panel, the keys and the mouse change from frame to frame.
struct ViewControls {
  std::uint64_t budget = 0;  // N, vertices
  float budgetPercent = 0;
  bool firstPassOnly = false, gpuReform = false, gpuStreaming = false;
  float minT = 0;
  int colorMode = 0;
  bool recording = false, playing = false, screenshotNow = false;
  std::vector<Camera> recorded, played;
  std::size_t playIndex = 0;
  std::string message;  // the last thing saved
};

// One window on one package: each frame steers the camera, selects, streams and draws the
// model, saves a screenshot when asked and draws the panel.
class PackageViewer {
 public:
  PackageViewer(const ViewOptions& options, const Package& package, const LodScene& scene,
                GLFWwindow* window, FramePipeline& pipeline)
      : o_(options),
        package_(package),
        scene_(scene),
        full_(scene.totalMaxVertices()),
        window_(window),
        pipeline_(pipeline),
        bounds_(packageBounds(package)) {
    control_.target = (bounds_.min + bounds_.max) * 0.5;
    control_.distance = 1.6 * length(bounds_.max - bounds_.min);
    control_.speed = 0.25 * length(bounds_.max - bounds_.min);
    control_.yaw = -kPi / 2;
    glfwGetCursorPos(window_, &lastX_, &lastY_);
  }

  ViewControls& controls() { return controls_; }
  std::uint64_t fullVertices() const { return full_; }
  std::uint64_t frames() const { return frame_ + 1; }

  Status run();
  // Still recording at exit (always so with --record and no button pressed): save it.
  Status saveRecording() const;

 private:
  void steer(double seconds);
  Camera nextCamera(std::uint32_t width, std::uint32_t height);
  Status drawModel(const Camera& camera);
  Status saveScreenshot(bool last, std::uint32_t width, std::uint32_t height);
  Status drawPanel();
  Status toggleRecording();

  const ViewOptions& o_;
  const Package& package_;
  const LodScene& scene_;
  const std::uint64_t full_;
  GLFWwindow* window_;
  FramePipeline& pipeline_;
  const Aabbd bounds_;
  CameraControl control_;
  ViewControls controls_;
  Selection selection_;
  FrameFigures figures_;
  double lastX_ = 0, lastY_ = 0;
  std::uint64_t frame_ = 0;
};

Status PackageViewer::run() {
  auto previous = std::chrono::steady_clock::now();
  while (!glfwWindowShouldClose(window_)) {
    LODFORGE_TRY(checkCancelled());
    glfwPollEvents();
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - previous).count();
    previous = now;
    int fbWidth = 0, fbHeight = 0;
    glfwGetFramebufferSize(window_, &fbWidth, &fbHeight);
    if (fbWidth <= 0 || fbHeight <= 0) continue;  // minimised
    const auto width = static_cast<std::uint32_t>(fbWidth);
    const auto height = static_cast<std::uint32_t>(fbHeight);
    steer(dt);
    const Camera camera = nextCamera(width, height);
    LODFORGE_TRY(drawModel(camera));
    // The last frame of a scripted run, or P: a screenshot of the model without the panel.
    const bool last = o_.stopAfter != 0 && frame_ + 1 >= o_.stopAfter;
    LODFORGE_TRY(saveScreenshot(last, width, height));
    LODFORGE_TRY(drawPanel());
    glfwSwapBuffers(window_);
    if (last) break;
    ++frame_;
  }
  return {};
}

// Mouse and keys, unless the panel has them: drag turns, the wheel zooms, WASD/QE fly.
void PackageViewer::steer(double seconds) {
  const ImGuiIO& io = ImGui::GetIO();
  double x = 0, y = 0;
  glfwGetCursorPos(window_, &x, &y);
  if (!io.WantCaptureMouse) {
    if (glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
      control_.yaw -= 0.005 * (x - lastX_);
      control_.pitch = std::clamp(control_.pitch + 0.005 * (y - lastY_), -1.5, 1.5);
      controls_.playing = false;
    }
    if (io.MouseWheel != 0) control_.distance *= std::pow(0.9, io.MouseWheel);
  }
  lastX_ = x;
  lastY_ = y;
  if (io.WantCaptureKeyboard) return;
  const Vec3d f = control_.forward(), r = normalizeOr(cross(f, Vec3d{0, 0, 1}), Vec3d{1, 0, 0});
  const double step = control_.speed * seconds;
  const auto key = [&](int k) { return glfwGetKey(window_, k) == GLFW_PRESS; };
  Vec3d move{0, 0, 0};
  if (key(GLFW_KEY_W)) move = move + f;
  if (key(GLFW_KEY_S)) move = move - f;
  if (key(GLFW_KEY_D)) move = move + r;
  if (key(GLFW_KEY_A)) move = move - r;
  if (key(GLFW_KEY_E)) move = move + Vec3d{0, 0, 1};
  if (key(GLFW_KEY_Q)) move = move - Vec3d{0, 0, 1};
  if (move.x != 0 || move.y != 0 || move.z != 0) {
    if (!control_.fly) {  // moving switches to fly from where the orbit stands
      control_.position = control_.target - f * control_.distance;
      control_.fly = true;
    }
    control_.position = control_.position + move * step;
    controls_.playing = false;
  }
  if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape)))
    glfwSetWindowShouldClose(window_, 1);
  if (ImGui::IsKeyPressed(GLFW_KEY_P)) controls_.screenshotNow = true;
}

// The steered camera, or the played path's next one (which the steering then follows).
Camera PackageViewer::nextCamera(std::uint32_t width, std::uint32_t height) {
  Camera camera = control_.camera(width, height, o_.fovY, bounds_);
  if (controls_.playing) {
    const auto& played = controls_.played;
    camera = played[controls_.playIndex % played.size()];
    camera.width = width;
    camera.height = height;
    control_.follow(camera);
    ++controls_.playIndex;
  }
  if (controls_.recording) controls_.recorded.push_back(camera);
  return camera;
}

// Select (§4), stream (§3.3) on the CPU or the GPU, re-form and draw.
Status PackageViewer::drawModel(const Camera& camera) {
  const auto t0 = std::chrono::steady_clock::now();
  selectTwoPass(scene_, camera, controls_.budget,
                {.minT = controls_.minT, .firstPassOnly = controls_.firstPassOnly}, selection_);
  const auto t1 = std::chrono::steady_clock::now();
  // CPU stream + upload, or the paper's GPU path where only the Δ crosses over.
  pipeline_.setStreaming(controls_.gpuStreaming ? Streaming::kGpu
                         : controls_.gpuReform  ? Streaming::kCpuGpuReform
                                                : Streaming::kCpu);
  auto stream = pipeline_.update(selection_.vertexCounts, selection_.triangleCounts);
  if (!stream) return stream.status();
  bindWindowFramebuffer();
  pipeline_.draw(camera, {.colorMode = static_cast<ColorMode>(controls_.colorMode)});
  const PipelineTimings& p = pipeline_.timings();
  figures_ = {milliseconds(t1 - t0),
              p.streamMs,
              p.uploadMs,
              p.reformMs,
              p.drawMs,
              *stream,
              selection_.totalVertices,
              selection_.totalTriangles,
              selection_.visibleObjects};
  return {};
}

Status PackageViewer::saveScreenshot(bool last, std::uint32_t width, std::uint32_t height) {
  if (!controls_.screenshotNow && !(last && !o_.screenshot.empty())) return {};
  const std::string name =
      !o_.screenshot.empty() && last ? o_.screenshot : fmt::format("lodforge-{:04}.png", frame_);
  LODFORGE_TRY(writePng(name, readPixels(0, width, height)));
  controls_.message = "saved " + name;
  controls_.screenshotNow = false;
  return {};
}

Status PackageViewer::drawPanel() {
  ViewControls& c = controls_;
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::Begin("lodforge");
  ImGui::Text("%s", o_.input.c_str());
  // The count stays exactly what --budget said until the slider moves.
  if (ImGui::SliderFloat("budget N (%)", &c.budgetPercent, 0.01f, 100.0f, "%.2f %%",
                         ImGuiSliderFlags_Logarithmic))
    c.budget = std::max<std::uint64_t>(
        1, static_cast<std::uint64_t>(
               std::llround(c.budgetPercent / 100.0 * static_cast<double>(full_))));
  ImGui::Text("N = %s of %s vertices", formatCount(c.budget).c_str(), formatCount(full_).c_str());
  ImGui::Checkbox("first pass only (Eq. 2-3)", &c.firstPassOnly);
  ImGui::SliderFloat("MinT (Eq. 3)", &c.minT, 0.0f, 1.0f);
  ImGui::Checkbox("GPU streaming (Δ upload, reassembly and reformation on the GPU)",
                  &c.gpuStreaming);
  if (!c.gpuStreaming) ImGui::Checkbox("GPU reformation (compute shader)", &c.gpuReform);
  const char* modes[] = {"shaded", "object", "LOD ratio", "normal"};
  ImGui::Combo("colour", &c.colorMode, modes, 4);
  ImGui::Separator();
  const FrameFigures& f = figures_;
  ImGui::Text("selection   %7.2f ms", f.selectionMs);
  ImGui::Text("generation  %7.2f ms", f.generationMs);
  ImGui::Text("upload      %7.2f ms", f.uploadMs);
  const bool onGpu = c.gpuStreaming || c.gpuReform;
  ImGui::Text("reformation %7.2f ms (%s)", onGpu ? f.reformMs : f.stream.reformationMs,
              onGpu ? "GPU" : "CPU, in generation");
  ImGui::Text("draw        %7.2f ms", f.drawMs);
  ImGui::Text("drawn: %s vertices, %s triangles, %s objects visible",
              formatCount(f.vertices).c_str(), formatCount(f.triangles).c_str(),
              formatCount(f.objects).c_str());
  ImGui::Text("streamed: %s read, %s moved", formatBytes(f.stream.bytesRead).c_str(),
              formatBytes(f.stream.bytesMoved).c_str());
  ImGui::Separator();
  ImGui::Text("camera: %s (drag, wheel; WASD/QE fly)", control_.fly ? "fly" : "orbit");
  if (ImGui::Button("orbit")) control_.fly = false;
  ImGui::SameLine();
  if (ImGui::Button(c.recording ? "stop recording" : "record path"))
    LODFORGE_TRY(toggleRecording());
  ImGui::SameLine();
  if (!c.played.empty() && ImGui::Button(c.playing ? "pause" : "play")) c.playing = !c.playing;
  if (ImGui::Button("screenshot (P)")) c.screenshotNow = true;
  if (!c.message.empty()) ImGui::Text("%s", c.message.c_str());
  ImGui::End();
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  return {};
}

// A recording that stops is saved at once (to --record or a numbered file) and ready to play.
Status PackageViewer::toggleRecording() {
  ViewControls& c = controls_;
  c.recording = !c.recording;
  if (c.recording) {
    c.recorded.clear();
    return {};
  }
  if (c.recorded.empty()) return {};
  const std::string file =
      o_.record.empty() ? fmt::format("lodforge-path-{:04}.json", frame_) : o_.record;
  LODFORGE_TRY(writeCameraPath(file, c.recorded, package_.origin()));
  c.message = fmt::format("saved {} cameras to {}", c.recorded.size(), file);
  c.played = c.recorded;
  c.playIndex = 0;
  return {};
}

Status PackageViewer::saveRecording() const {
  if (!controls_.recording || o_.record.empty() || controls_.recorded.empty()) return {};
  return writeCameraPath(o_.record, controls_.recorded, package_.origin());
}

// The cameras of --play, if given.
Result<std::vector<Camera>> playedPath(const ViewOptions& o, const Package& package) {
  if (o.play.empty()) return std::vector<Camera>{};
  PathChoice choice = o;
  choice.path = o.play;
  return cameraPath(choice, package);
}

Status runView(const Global& global, const ViewOptions& o) {
  LODFORGE_TRY(claimIfGiven(o.record, jsonOutput(), {o.input}));
  LODFORGE_TRY(claimIfGiven(o.screenshot, pngOutput(), {o.input}));
  Result<Package> package = Package::open(o.input);
  if (!package) return package.status();
  auto colorMode = parseColorMode(o.color);
  if (!colorMode) return colorMode.status();
  const LodScene scene = LodScene::fromPackage(*package);
  const std::uint64_t full = scene.totalMaxVertices();
  auto budget = parseBudget(o.budget, full);
  if (!budget) return budget.status();
  std::uint32_t width = 0, height = 0;
  LODFORGE_TRY(parseSize(o.size, width, height));
  Result<std::vector<Camera>> played = playedPath(o, *package);
  if (!played) return played.status();
  auto gl = GlContext::window(width, height, "lodforge — " + o.input);
  if (!gl) return gl.status();
  GLFWwindow* window = (*gl)->glfwWindow();

  // Buffers for the whole model, so the budget slider can go to 100 %.
  const StreamCapacity capacity = StreamCapacity::forVertices(*package, full);
  // Every arrangement prepared: the panel switches between them.
  auto pipeline = FramePipeline::create(*package, capacity, Streaming::kCpu, /*switchable=*/true);
  if (!pipeline) return pipeline.status();
  const ImGuiPanel panel(window);

  PackageViewer viewer(o, *package, scene, window, *pipeline);
  ViewControls& controls = viewer.controls();
  controls.budget = *budget;
  controls.budgetPercent =
      static_cast<float>(100.0 * static_cast<double>(*budget) / static_cast<double>(full));
  controls.firstPassOnly = o.firstPassOnly;
  controls.gpuReform = o.gpuReform;
  controls.gpuStreaming = o.gpuStream;
  controls.minT = static_cast<float>(o.minT);
  controls.colorMode = static_cast<int>(*colorMode);
  controls.recording = !o.record.empty();
  controls.played = std::move(*played);
  controls.playing = !controls.played.empty();
  LODFORGE_TRY(viewer.run());
  LODFORGE_TRY(viewer.saveRecording());
  say(global, fmt::format("{} frames shown{}", viewer.frames(),
                          o.record.empty() ? "" : fmt::format(", path written to {}", o.record)));
  return {};
}

}  // namespace

void addView(CLI::App& app, const Global& global, Run& run) {
  auto o = std::make_shared<ViewOptions>();
  CLI::App* sub = app.add_subcommand("view", "Interactive viewer (needs a display; see render)");
  sub->add_option("PACKAGE", o->input, "A .lfp package or a .lfc point package")->required();
  sub->add_option("--budget", o->budget, "Starting vertex budget: a count (3M) or a share (10%)")
      ->capture_default_str();
  sub->add_option("--size", o->size, "Window WIDTHxHEIGHT")->capture_default_str();
  sub->add_option("--fov", o->fovY, "Vertical field of view, degrees")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 179.0));
  sub->add_option("--play", o->play, "Play a camera path: orbit, fly or a path JSON file");
  sub->add_option("--frames", o->frames, "Frames of a generated --play path")
      ->capture_default_str();
  sub->add_option("--record", o->record, "Write the cameras shown as a path JSON file at exit");
  sub->add_option("--stop-after", o->stopAfter, "Close after this many frames (scripted runs)");
  sub->add_option("--screenshot", o->screenshot, "With --stop-after: a PNG of the last frame");
  sub->add_option("--color", o->color, "shaded, object, lod or normal")->capture_default_str();
  sub->add_flag("--gpu-reform", o->gpuReform, "Start with the compute-shader reformation");
  sub->add_flag("--gpu-stream", o->gpuStream,
                "Start streaming on the GPU (§3.3 as the paper runs it)");
  sub->add_flag("--first-pass-only", o->firstPassOnly, "Start with Eq. 2 and 3 only");
  sub->add_option("--min-t", o->minT, "Eq. 3's MinT")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  auto cloud = std::make_shared<CloudRunOptions>();
  addCloudOptions(*sub, *cloud, /*severalRadii=*/false);
  sub->callback([&global, &run, o, cloud] {
    if (fileExtension(o->input) == "lfc") {
      takePackageRun(*cloud, o->input, *o);
      cloud->play = !o->play.empty();
      cloud->path = o->play.empty() ? "orbit" : o->play;
      cloud->stopAfter = o->stopAfter;
      cloud->screenshot = o->screenshot;
      run = [&global, cloud] { return runCloudView(global, *cloud); };
      return;
    }
    run = [&global, o] { return runView(global, *o); };
  });
}

}  // namespace lodforge::cli
