// `lodforge view cloud.lfc` and `lodforge bench cloud.lfc`: the points paper's runtime (§4.1
// gaze-driven selection, §4.2 paging) in a window whose fovea follows the mouse, and along a
// camera path with a moving gaze, timed (the paper's §5 table: frame time against points used).
#include <chrono>
#include <cmath>
#include <numbers>

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <fmt/format.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include "cloud.h"
#include "imgui_panel.h"

#include "lodforge/core/file.h"
#include "lodforge/core/units.h"
#include "lodforge/render/context.h"
#include "lodforge/render/image.h"
#include "lodforge/render/point_renderer.h"
#include "lodforge/render/renderer.h"
#include "lodforge/runtime/path.h"
#include "outputs.h"
#include "view_options.h"

namespace lodforge::cli {

namespace {

// The gaze along a benchmark path: a circle around the screen's centre, one turn per 40 frames,
// so the fovea sweeps over blocks and the pager works.
void benchGaze(FoveaOptions& fovea, const Camera& camera, std::size_t frame) {
  const double angle = 2 * std::numbers::pi * static_cast<double>(frame) / 40;
  fovea.gazeX = camera.width * (0.5 + 0.3 * std::cos(angle));
  fovea.gazeY = camera.height * (0.5 + 0.3 * std::sin(angle));
}

Result<std::vector<Camera>> cloudPath(const CloudRunOptions& o, const Aabbd& bounds) {
  std::uint32_t width = 0, height = 0;
  LODFORGE_TRY(parseSize(o.size, width, height));
  PathOptions path{static_cast<std::size_t>(o.frames), width, height, o.fovY};
  if (o.path == "orbit") return orbitPath(bounds, path);
  if (o.path == "fly") return flyThroughPath(bounds, path);
  Result<std::vector<Camera>> cameras = readCameraPath(o.path, {}, bounds);
  if (!cameras) return cameras.status();
  if (cameras->size() > o.frames) cameras->resize(o.frames);
  return cameras;
}

}  // namespace

void addCloudOptions(CLI::App& sub, CloudRunOptions& options, bool severalRadii) {
  auto* fovea = sub.add_option(
      "--fovea", options.foveaRadii,
      severalRadii ? "Point packages: fovea radii in pixels, one run each (default 200)"
                   : "Point packages: fovea radius in pixels (default 200)");
  if (severalRadii) {
    fovea->delimiter(',');
  } else {
    fovea->expected(1);
  }
  sub.add_option("--foveal-splat", options.fovealSplat,
                 "Point packages: largest splat in the fovea, pixels (default 2)")
      ->check(CLI::Range(0.1, 100.0));
  sub.add_option("--resident-blocks", options.residentBlocks,
                 "Point packages: blocks kept in memory (default 8, as in the paper)")
      ->check(CLI::Range(1, 1'000'000));
  sub.add_option("--loads-per-frame", options.loadsPerFrame,
                 "Point packages: segment files read per frame at most (default 2)")
      ->check(CLI::Range(1, 1'000'000));
}

void takePackageRun(CloudRunOptions& cloud, const std::string& input, const PathChoice& choice) {
  static_cast<PathChoice&>(cloud) = choice;
  cloud.input = input;
  if (cloud.foveaRadii.empty()) cloud.foveaRadii = {200};
}

namespace {

// One frame of the point benchmark.
struct CloudFrame {
  double selectMs = 0, pageMs = 0, renderMs = 0;
  std::size_t splats = 0, loads = 0;
  std::uint64_t inputPoints = 0;
};

// With --render: a headless context, a target of the path's size and the splat renderer.
struct HeadlessSplats {
  std::unique_ptr<GlContext> context;
  std::optional<Framebuffer> framebuffer;
  std::optional<PointRenderer> renderer;
};

Result<HeadlessSplats> startHeadless(const Camera& first) {
  HeadlessSplats headless;
  Result<std::unique_ptr<GlContext>> gl = GlContext::headless();
  if (!gl) return gl.status();
  headless.context = std::move(*gl);
  Result<Framebuffer> target = Framebuffer::create(first.width, first.height);
  if (!target) return target.status();
  headless.framebuffer.emplace(std::move(*target));
  Result<PointRenderer> renderer = PointRenderer::create();
  if (!renderer) return renderer.status();
  headless.renderer.emplace(std::move(*renderer));
  return headless;
}

// The path once with a fovea of `radius`: select (§4.1), page (§4.2) and, headless, draw.
Result<std::vector<CloudFrame>> runFovea(const CloudFile& cloud, const std::vector<Camera>& cameras,
                                         const CloudRunOptions& o, double radius,
                                         HeadlessSplats* headless) {
  BlockPager pager(cloud, o.residentBlocks, o.loadsPerFrame);
  FoveaOptions fovea;
  fovea.radius = radius;
  fovea.fovealSplat = o.fovealSplat;
  PointSelection selection;
  std::vector<CloudFrame> frames;
  for (std::size_t f = 0; f < cameras.size(); ++f) {
    const Camera& camera = cameras[f];
    benchGaze(fovea, camera, f);
    CloudFrame frame;
    auto t0 = std::chrono::steady_clock::now();
    selectPoints(cloud, pager, camera, fovea, f + 1, selection);
    auto t1 = std::chrono::steady_clock::now();
    Result<std::size_t> loads = pager.update(selection.wanted, f + 1);
    if (!loads) return loads.status();
    auto t2 = std::chrono::steady_clock::now();
    frame.selectMs = milliseconds(t1 - t0);
    frame.pageMs = milliseconds(t2 - t1);
    frame.loads = *loads;
    frame.splats = selection.size();
    frame.inputPoints = selection.inputPoints;
    if (headless) {
      const auto r0 = std::chrono::steady_clock::now();
      headless->framebuffer->bind();
      headless->renderer->upload(selection);
      headless->renderer->draw(camera);
      headless->context->finish();
      frame.renderMs = milliseconds(std::chrono::steady_clock::now() - r0);
    }
    frames.push_back(frame);
  }
  return frames;
}

void printRunHeader(const Global& global, const CloudRunOptions& o, const CloudFile& cloud,
                    const std::vector<Camera>& cameras) {
  say(global,
      fmt::format("{}: {} points in {} blocks, Part II {} splats; {} frames of {} "
                  "({}x{}), gaze circling the centre; {} resident blocks, {} loads/frame",
                  o.input, formatCount(cloud.header().pointCount),
                  formatCount(cloud.header().blockCount), formatCount(cloud.header().residentCount),
                  cameras.size(), o.path, cameras.front().width, cameras.front().height,
                  o.residentBlocks, o.loadsPerFrame));
  fmt::print(
      "| fovea px | splat px | mean splats | max splats | select ms | page ms |{} loads/frame "
      "(max) | input pts/frame |\n",
      o.render ? " render ms |" : "");
  fmt::print(
      "|----------|----------|-------------|------------|-----------|---------|{}"
      "-------------------|-----------------|\n",
      o.render ? "-----------|" : "");
}

void printRunRow(const CloudRunOptions& o, double radius, const std::vector<CloudFrame>& frames) {
  CloudFrame mean;
  std::size_t maxSplats = 0, maxLoads = 0;
  for (const CloudFrame& f : frames) {
    mean.selectMs += f.selectMs / static_cast<double>(frames.size());
    mean.pageMs += f.pageMs / static_cast<double>(frames.size());
    mean.renderMs += f.renderMs / static_cast<double>(frames.size());
    mean.splats += f.splats;
    mean.loads += f.loads;
    mean.inputPoints += f.inputPoints;
    maxSplats = std::max(maxSplats, f.splats);
    maxLoads = std::max(maxLoads, f.loads);
  }
  const double n = static_cast<double>(frames.size());
  fmt::print(
      "| {:8.0f} | {:8.1f} | {:>11} | {:>10} | {:9.2f} | {:7.2f} |{} {:8.2f} ({:>4}) | "
      "{:>15} |\n",
      radius, o.fovealSplat,
      formatCount(static_cast<std::uint64_t>(static_cast<double>(mean.splats) / n)),
      formatCount(maxSplats), mean.selectMs, mean.pageMs,
      o.render ? fmt::format(" {:9.2f} |", mean.renderMs) : std::string(),
      static_cast<double>(mean.loads) / n, maxLoads,
      formatCount(static_cast<std::uint64_t>(static_cast<double>(mean.inputPoints) / n)));
}

nlohmann::json runJson(const CloudRunOptions& o, double radius,
                       const std::vector<CloudFrame>& frames) {
  nlohmann::json run = {
      {"foveaRadius", radius}, {"fovealSplat", o.fovealSplat}, {"frames", nlohmann::json::array()}};
  for (const CloudFrame& f : frames)
    run["frames"].push_back({{"splats", f.splats},
                             {"selectMs", f.selectMs},
                             {"pageMs", f.pageMs},
                             {"renderMs", f.renderMs},
                             {"loads", f.loads},
                             {"inputPoints", f.inputPoints}});
  return run;
}

// The paper's §5 table: frame time by points used, over every run.
void printFrameTimes(const CloudRunOptions& o, const std::vector<CloudFrame>& all) {
  fmt::print("\nframe time by splats drawn (all runs{})\n",
             o.render ? ", select + page + render" : ", select + page");
  fmt::print(
      "| splats used | frames | mean ms | max ms |\n|-------------|--------|---------|--------|\n");
  const std::uint64_t edges[] = {10'000, 20'000, 30'000, 50'000, 100'000, 200'000, 500'000};
  std::uint64_t lower = 0;
  for (std::size_t e = 0; e <= std::size(edges); ++e) {
    const std::uint64_t upper = e < std::size(edges) ? edges[e] : ~std::uint64_t{0};
    double sum = 0, worst = 0;
    std::size_t count = 0;
    for (const CloudFrame& f : all) {
      if (f.splats < lower || f.splats >= upper) continue;
      const double ms = f.selectMs + f.pageMs + f.renderMs;
      sum += ms;
      worst = std::max(worst, ms);
      ++count;
    }
    if (count > 0)
      fmt::print("| {:>11} | {:>6} | {:7.2f} | {:6.2f} |\n",
                 e < std::size(edges) ? "< " + formatCount(upper) : ">= " + formatCount(lower),
                 count, sum / static_cast<double>(count), worst);
    lower = upper;
  }
}

}  // namespace

Status runCloudBench(const Global& global, const CloudRunOptions& o) {
  LODFORGE_TRY(claimIfGiven(o.json, jsonOutput(), {o.input}));
  Result<CloudFile> cloud = CloudFile::open(o.input);
  if (!cloud) return cloud.status();
  Result<std::vector<Camera>> cameras = cloudPath(o, cloud->header().bounds);
  if (!cameras) return cameras.status();
  std::optional<HeadlessSplats> headless;
  if (o.render) {
    Result<HeadlessSplats> started = startHeadless(cameras->front());
    if (!started) return started.status();
    headless.emplace(std::move(*started));
  }
  nlohmann::json json = {{"file", o.input},
                         {"points", cloud->header().pointCount},
                         {"blocks", cloud->header().blockCount},
                         {"runs", nlohmann::json::array()}};
  printRunHeader(global, o, *cloud, *cameras);
  std::vector<CloudFrame> all;
  for (double radius : o.foveaRadii) {
    Result<std::vector<CloudFrame>> frames =
        runFovea(*cloud, *cameras, o, radius, headless ? &*headless : nullptr);
    if (!frames) return frames.status();
    printRunRow(o, radius, *frames);
    json["runs"].push_back(runJson(o, radius, *frames));
    all.insert(all.end(), frames->begin(), frames->end());
  }
  printFrameTimes(o, all);
  if (!o.json.empty()) LODFORGE_TRY(OutputFile::writeWhole(o.json, json.dump(2)));
  return {};
}

namespace {

// One window on one point package: each frame orbits the camera (or plays the path), puts the
// fovea where the mouse is, selects, pages and draws the splats, and draws the panel.
class CloudViewer {
 public:
  CloudViewer(const CloudRunOptions& options, const CloudFile& cloud, GlContext& gl,
              PointRenderer& renderer, std::vector<Camera> played)
      : o_(options),
        cloud_(cloud),
        gl_(gl),
        window_(gl.glfwWindow()),
        renderer_(renderer),
        bounds_(cloud.header().bounds),
        played_(std::move(played)),
        pager_(cloud, options.residentBlocks, options.loadsPerFrame),
        distance_(1.2 * length(bounds_.max - bounds_.min)),
        radius_(static_cast<float>(options.foveaRadii.front())),
        splat_(static_cast<float>(options.fovealSplat)) {
    glfwGetCursorPos(window_, &lastX_, &lastY_);
  }

  Status run();
  std::uint64_t frames() const { return frame_; }
  std::uint64_t loads() const { return pager_.loads(); }

 private:
  // Orbit around the centre: drag to turn, wheel to zoom.
  void steer(double x, double y);
  Camera nextCamera(int fbWidth, int fbHeight) const;
  Status drawPoints(const Camera& camera, double gazeX, double gazeY);
  void drawPanel();

  const CloudRunOptions& o_;
  const CloudFile& cloud_;
  GlContext& gl_;
  GLFWwindow* window_;
  PointRenderer& renderer_;
  const Aabbd bounds_;
  const std::vector<Camera> played_;
  BlockPager pager_;
  PointSelection selection_;
  double yaw_ = -std::numbers::pi / 2, pitch_ = 0.5, distance_;
  float radius_, splat_;  // the panel's fovea radius and foveal splat size, pixels
  double lastX_ = 0, lastY_ = 0, selectMs_ = 0, drawMs_ = 0;
  std::size_t loadsLastFrame_ = 0;
  std::uint64_t frame_ = 0;
};

Status CloudViewer::run() {
  while (!glfwWindowShouldClose(window_)) {
    ++frame_;
    glfwPollEvents();
    int fbWidth = 0, fbHeight = 0, winWidth = 0, winHeight = 0;
    glfwGetFramebufferSize(window_, &fbWidth, &fbHeight);
    glfwGetWindowSize(window_, &winWidth, &winHeight);
    double x = 0, y = 0;
    glfwGetCursorPos(window_, &x, &y);
    steer(x, y);
    const Camera camera = nextCamera(fbWidth, fbHeight);
    // The gaze is the mouse, in framebuffer pixels (window and framebuffer may differ).
    const double scale = winWidth > 0 ? static_cast<double>(fbWidth) / winWidth : 1;
    LODFORGE_TRY(drawPoints(camera, o_.play ? -1 : x * scale, o_.play ? -1 : y * scale));
    const bool last = o_.stopAfter > 0 && frame_ >= o_.stopAfter;
    if (last && !o_.screenshot.empty()) {
      gl_.finish();
      LODFORGE_TRY(writePng(o_.screenshot, readPixels(0, camera.width, camera.height)));
    }
    drawPanel();
    glfwSwapBuffers(window_);
    if (last) break;
  }
  return {};
}

void CloudViewer::steer(double x, double y) {
  const ImGuiIO& io = ImGui::GetIO();
  if (!io.WantCaptureMouse) {
    if (glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
      yaw_ -= (x - lastX_) * 0.005;
      pitch_ = std::clamp(pitch_ + (y - lastY_) * 0.005, -1.5, 1.5);
    }
    distance_ *= std::pow(0.9, io.MouseWheel);
  }
  lastX_ = x;
  lastY_ = y;
}

Camera CloudViewer::nextCamera(int fbWidth, int fbHeight) const {
  const auto width = static_cast<std::uint32_t>(std::max(1, fbWidth));
  const auto height = static_cast<std::uint32_t>(std::max(1, fbHeight));
  if (!played_.empty()) {
    Camera camera = played_[(frame_ - 1) % played_.size()];
    camera.width = width;
    camera.height = height;
    return camera;
  }
  const Vec3d forward{std::cos(pitch_) * std::cos(yaw_), std::cos(pitch_) * std::sin(yaw_),
                      -std::sin(pitch_)};
  const Vec3d eye = bounds_.center() - forward * distance_;
  Camera camera = Camera::lookAt(eye, bounds_.center(), {0, 0, 1}, o_.fovY, width, height);
  fitClipPlanes(camera, bounds_);
  return camera;
}

// Select the splats around the gaze (§4.1), page the blocks they need (§4.2), draw.
Status CloudViewer::drawPoints(const Camera& camera, double gazeX, double gazeY) {
  FoveaOptions fovea;
  fovea.gazeX = gazeX;
  fovea.gazeY = gazeY;
  fovea.radius = radius_;
  fovea.fovealSplat = splat_;
  const auto t0 = std::chrono::steady_clock::now();
  selectPoints(cloud_, pager_, camera, fovea, frame_, selection_);
  Result<std::size_t> loads = pager_.update(selection_.wanted, frame_);
  if (!loads) return loads.status();
  loadsLastFrame_ = *loads;
  const auto t1 = std::chrono::steady_clock::now();
  bindWindowFramebuffer();
  renderer_.upload(selection_);
  renderer_.draw(camera);
  const auto t2 = std::chrono::steady_clock::now();
  selectMs_ = milliseconds(t1 - t0);
  drawMs_ = milliseconds(t2 - t1);
  return {};
}

void CloudViewer::drawPanel() {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::Begin("lodforge points");
  ImGui::Text("%s: %s points, %s blocks", o_.input.c_str(),
              formatCount(cloud_.header().pointCount).c_str(),
              formatCount(cloud_.header().blockCount).c_str());
  ImGui::SliderFloat("fovea radius (px)", &radius_, 10.0f, 2000.0f, "%.0f",
                     ImGuiSliderFlags_Logarithmic);
  ImGui::SliderFloat("foveal splat (px)", &splat_, 0.5f, 32.0f, "%.1f",
                     ImGuiSliderFlags_Logarithmic);
  ImGui::Text("splats %s (standing for %s points)", formatCount(selection_.size()).c_str(),
              formatCount(selection_.inputPoints).c_str());
  ImGui::Text("blocks: %u visible, %u refined, %zu resident of %zu, %zu loaded this frame",
              selection_.visibleBlocks, selection_.refinedBlocks, pager_.residentCount(),
              o_.residentBlocks, loadsLastFrame_);
  ImGui::Text("select + page %6.2f ms, draw %6.2f ms", selectMs_, drawMs_);
  ImGui::Text("drag: turn, wheel: zoom, the fovea follows the mouse");
  ImGui::End();
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

}  // namespace

Status runCloudView(const Global& global, const CloudRunOptions& o) {
  LODFORGE_TRY(claimIfGiven(o.screenshot, pngOutput(), {o.input}));
  Result<CloudFile> cloud = CloudFile::open(o.input);
  if (!cloud) return cloud.status();
  std::uint32_t width = 0, height = 0;
  LODFORGE_TRY(parseSize(o.size, width, height));
  auto gl = GlContext::window(width, height, "lodforge — " + o.input);
  if (!gl) return gl.status();
  Result<PointRenderer> renderer = PointRenderer::create();
  if (!renderer) return renderer.status();
  const ImGuiPanel panel((*gl)->glfwWindow());
  std::vector<Camera> played;
  if (o.play) {
    Result<std::vector<Camera>> path = cloudPath(o, cloud->header().bounds);
    if (!path) return path.status();
    played = std::move(*path);
  }
  CloudViewer viewer(o, *cloud, **gl, *renderer, std::move(played));
  LODFORGE_TRY(viewer.run());
  say(global, fmt::format("{} frames shown, {} block loads", viewer.frames(), viewer.loads()));
  return {};
}

}  // namespace lodforge::cli
