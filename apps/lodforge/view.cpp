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

double milliseconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
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
  std::vector<Camera> played;
  if (!o.play.empty()) {
    PathChoice choice = o;
    choice.path = o.play;
    auto path = cameraPath(choice, *package);
    if (!path) return path.status();
    played = std::move(*path);
  }
  auto gl = GlContext::window(width, height, "lodforge — " + o.input);
  if (!gl) return gl.status();
  GLFWwindow* window = (*gl)->glfwWindow();

  // Buffers for the whole model, so the budget slider can go to 100 %.
  const StreamCapacity capacity = StreamCapacity::forVertices(*package, full);
  // Every arrangement prepared: the panel switches between them.
  auto pipeline = FramePipeline::create(*package, capacity, Streaming::kCpu, /*switchable=*/true);
  if (!pipeline) return pipeline.status();

  const ImGuiPanel panel(window);

  const Aabbd bounds = packageBounds(*package);
  CameraControl control;
  control.target = (bounds.min + bounds.max) * 0.5;
  control.distance = 1.6 * length(bounds.max - bounds.min);
  control.speed = 0.25 * length(bounds.max - bounds.min);
  control.yaw = -kPi / 2;

  float budgetPercent =
      static_cast<float>(100.0 * static_cast<double>(*budget) / static_cast<double>(full));
  std::uint64_t n = *budget;
  bool firstPassOnly = o.firstPassOnly, gpuReform = o.gpuReform, gpuStreaming = o.gpuStream;
  float minT = static_cast<float>(o.minT);
  int mode = static_cast<int>(*colorMode);
  bool recording = !o.record.empty();
  std::vector<Camera> recorded;
  std::size_t playIndex = 0;
  bool playing = !played.empty();
  Selection selection;
  FrameFigures figures;
  double lastX = 0, lastY = 0;
  glfwGetCursorPos(window, &lastX, &lastY);
  auto previous = std::chrono::steady_clock::now();
  std::uint64_t frame = 0;
  bool screenshotNow = false;
  std::string message;

  while (!glfwWindowShouldClose(window)) {
    LODFORGE_TRY(checkCancelled());
    glfwPollEvents();
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - previous).count();
    previous = now;
    int fbWidth = 0, fbHeight = 0;
    glfwGetFramebufferSize(window, &fbWidth, &fbHeight);
    if (fbWidth <= 0 || fbHeight <= 0) continue;  // minimised

    // Input, unless the panel has it.
    const ImGuiIO& io = ImGui::GetIO();
    double x = 0, y = 0;
    glfwGetCursorPos(window, &x, &y);
    if (!io.WantCaptureMouse) {
      if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
        control.yaw -= 0.005 * (x - lastX);
        control.pitch = std::clamp(control.pitch + 0.005 * (y - lastY), -1.5, 1.5);
        playing = false;
      }
      if (io.MouseWheel != 0) control.distance *= std::pow(0.9, io.MouseWheel);
    }
    lastX = x;
    lastY = y;
    if (!io.WantCaptureKeyboard) {
      const Vec3d f = control.forward(), r = normalizeOr(cross(f, Vec3d{0, 0, 1}), Vec3d{1, 0, 0});
      const double step = control.speed * dt;
      const auto key = [&](int k) { return glfwGetKey(window, k) == GLFW_PRESS; };
      Vec3d move{0, 0, 0};
      if (key(GLFW_KEY_W)) move = move + f;
      if (key(GLFW_KEY_S)) move = move - f;
      if (key(GLFW_KEY_D)) move = move + r;
      if (key(GLFW_KEY_A)) move = move - r;
      if (key(GLFW_KEY_E)) move = move + Vec3d{0, 0, 1};
      if (key(GLFW_KEY_Q)) move = move - Vec3d{0, 0, 1};
      if (move.x != 0 || move.y != 0 || move.z != 0) {
        if (!control.fly) {  // moving switches to fly from where the orbit stands
          control.position = control.target - f * control.distance;
          control.fly = true;
        }
        control.position = control.position + move * step;
        playing = false;
      }
      if (ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape)))
        glfwSetWindowShouldClose(window, 1);
      if (ImGui::IsKeyPressed(GLFW_KEY_P)) screenshotNow = true;
    }
    Camera camera = control.camera(static_cast<std::uint32_t>(fbWidth),
                                   static_cast<std::uint32_t>(fbHeight), o.fovY, bounds);
    if (playing) {
      camera = played[playIndex % played.size()];
      camera.width = static_cast<std::uint32_t>(fbWidth);
      camera.height = static_cast<std::uint32_t>(fbHeight);
      control.follow(camera);
      ++playIndex;
    }
    if (recording) recorded.push_back(camera);

    // Select, stream, re-form, draw.
    const auto t0 = std::chrono::steady_clock::now();
    selectTwoPass(scene, camera, n, {.minT = minT, .firstPassOnly = firstPassOnly}, selection);
    const auto t1 = std::chrono::steady_clock::now();
    // CPU stream + upload, or the paper's GPU path where only the Δ crosses over.
    pipeline->setStreaming(gpuStreaming ? Streaming::kGpu
                           : gpuReform  ? Streaming::kCpuGpuReform
                                        : Streaming::kCpu);
    auto stream = pipeline->update(selection.vertexCounts, selection.triangleCounts);
    if (!stream) return stream.status();
    bindWindowFramebuffer();
    pipeline->draw(camera, {.colorMode = static_cast<ColorMode>(mode)});
    const PipelineTimings& p = pipeline->timings();
    figures = {milliseconds(t1 - t0),
               p.streamMs,
               p.uploadMs,
               p.reformMs,
               p.drawMs,
               *stream,
               selection.totalVertices,
               selection.totalTriangles,
               selection.visibleObjects};

    // The last frame of a scripted run, or P: a screenshot of the model without the panel.
    const bool last = o.stopAfter != 0 && frame + 1 >= o.stopAfter;
    if (screenshotNow || (last && !o.screenshot.empty())) {
      const std::string name =
          !o.screenshot.empty() && last ? o.screenshot : fmt::format("lodforge-{:04}.png", frame);
      const Image image =
          readPixels(0, static_cast<std::uint32_t>(fbWidth), static_cast<std::uint32_t>(fbHeight));
      LODFORGE_TRY(writePng(name, image));
      message = "saved " + name;
      screenshotNow = false;
    }

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
    ImGui::Begin("lodforge");
    ImGui::Text("%s", o.input.c_str());
    // The count stays exactly what --budget said until the slider moves.
    if (ImGui::SliderFloat("budget N (%)", &budgetPercent, 0.01f, 100.0f, "%.2f %%",
                           ImGuiSliderFlags_Logarithmic))
      n = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(
                                         budgetPercent / 100.0 * static_cast<double>(full))));
    ImGui::Text("N = %s of %s vertices", formatCount(n).c_str(), formatCount(full).c_str());
    ImGui::Checkbox("first pass only (Eq. 2-3)", &firstPassOnly);
    ImGui::SliderFloat("MinT (Eq. 3)", &minT, 0.0f, 1.0f);
    ImGui::Checkbox("GPU streaming (Δ upload, reassembly and reformation on the GPU)",
                    &gpuStreaming);
    if (!gpuStreaming) ImGui::Checkbox("GPU reformation (compute shader)", &gpuReform);
    const char* modes[] = {"shaded", "object", "LOD ratio", "normal"};
    ImGui::Combo("colour", &mode, modes, 4);
    ImGui::Separator();
    ImGui::Text("selection   %7.2f ms", figures.selectionMs);
    ImGui::Text("generation  %7.2f ms", figures.generationMs);
    ImGui::Text("upload      %7.2f ms", figures.uploadMs);
    const bool onGpu = gpuStreaming || gpuReform;
    ImGui::Text("reformation %7.2f ms (%s)",
                onGpu ? figures.reformMs : figures.stream.reformationMs,
                onGpu ? "GPU" : "CPU, in generation");
    ImGui::Text("draw        %7.2f ms", figures.drawMs);
    ImGui::Text("drawn: %s vertices, %s triangles, %s objects visible",
                formatCount(figures.vertices).c_str(), formatCount(figures.triangles).c_str(),
                formatCount(figures.objects).c_str());
    ImGui::Text("streamed: %s read, %s moved", formatBytes(figures.stream.bytesRead).c_str(),
                formatBytes(figures.stream.bytesMoved).c_str());
    ImGui::Separator();
    ImGui::Text("camera: %s (drag, wheel; WASD/QE fly)", control.fly ? "fly" : "orbit");
    if (ImGui::Button("orbit")) control.fly = false;
    ImGui::SameLine();
    if (ImGui::Button(recording ? "stop recording" : "record path")) {
      recording = !recording;
      if (recording) {
        recorded.clear();
      } else if (!recorded.empty()) {
        // Saved at once (to --record or a numbered file), and ready to play back.
        const std::string file =
            o.record.empty() ? fmt::format("lodforge-path-{:04}.json", frame) : o.record;
        LODFORGE_TRY(writeCameraPath(file, recorded, package->origin()));
        message = fmt::format("saved {} cameras to {}", recorded.size(), file);
        played = recorded;
        playIndex = 0;
      }
    }
    ImGui::SameLine();
    if (!played.empty() && ImGui::Button(playing ? "pause" : "play")) playing = !playing;
    if (ImGui::Button("screenshot (P)")) screenshotNow = true;
    if (!message.empty()) ImGui::Text("%s", message.c_str());
    ImGui::End();
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glfwSwapBuffers(window);
    if (last) break;
    ++frame;
  }
  // Still recording at exit (always so with --record and no button pressed): save it.
  if (recording && !o.record.empty() && !recorded.empty())
    LODFORGE_TRY(writeCameraPath(o.record, recorded, package->origin()));
  say(global, fmt::format("{} frames shown{}", frame + 1,
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
      if (cloud->foveaRadii.empty()) cloud->foveaRadii = {200};
      run = [&global, cloud] { return runCloudView(global, *cloud); };
      return;
    }
    run = [&global, o] { return runView(global, *o); };
  });
}

}  // namespace lodforge::cli
