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

double milliseconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

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
}

Status runCloudBench(const Global& global, const CloudRunOptions& o) {
  LODFORGE_TRY(claimIfGiven(o.json, jsonOutput(), {o.input}));
  Result<CloudFile> cloud = CloudFile::open(o.input);
  if (!cloud) return cloud.status();
  Result<std::vector<Camera>> cameras = cloudPath(o, cloud->header().bounds);
  if (!cameras) return cameras.status();
  std::unique_ptr<GlContext> context;
  std::optional<Framebuffer> framebuffer;
  std::optional<PointRenderer> renderer;
  if (o.render) {
    Result<std::unique_ptr<GlContext>> gl = GlContext::headless();
    if (!gl) return gl.status();
    context = std::move(*gl);
    Result<Framebuffer> target =
        Framebuffer::create(cameras->front().width, cameras->front().height);
    if (!target) return target.status();
    framebuffer.emplace(std::move(*target));
    Result<PointRenderer> r = PointRenderer::create();
    if (!r) return r.status();
    renderer.emplace(std::move(*r));
  }
  struct Frame {
    double selectMs = 0, pageMs = 0, renderMs = 0;
    std::size_t splats = 0, loads = 0;
    std::uint64_t inputPoints = 0;
  };
  nlohmann::json json = {{"file", o.input},
                         {"points", cloud->header().pointCount},
                         {"blocks", cloud->header().blockCount},
                         {"runs", nlohmann::json::array()}};
  say(global, fmt::format("{}: {} points in {} blocks, Part II {} splats; {} frames of {} "
                          "({}x{}), gaze circling the centre; {} resident blocks, {} loads/frame",
                          o.input, formatCount(cloud->header().pointCount),
                          formatCount(cloud->header().blockCount),
                          formatCount(cloud->header().residentCount), cameras->size(), o.path,
                          cameras->front().width, cameras->front().height, o.residentBlocks,
                          o.loadsPerFrame));
  fmt::print(
      "| fovea px | splat px | mean splats | max splats | select ms | page ms |{} loads/frame "
      "(max) | input pts/frame |\n",
      o.render ? " render ms |" : "");
  fmt::print(
      "|----------|----------|-------------|------------|-----------|---------|{}"
      "-------------------|-----------------|\n",
      o.render ? "-----------|" : "");
  std::vector<Frame> all;
  for (double radius : o.foveaRadii) {
    BlockPager pager(*cloud, o.residentBlocks, o.loadsPerFrame);
    FoveaOptions fovea;
    fovea.radius = radius;
    fovea.fovealSplat = o.fovealSplat;
    PointSelection selection;
    std::vector<Frame> frames;
    for (std::size_t f = 0; f < cameras->size(); ++f) {
      const Camera& camera = (*cameras)[f];
      benchGaze(fovea, camera, f);
      Frame frame;
      auto t0 = std::chrono::steady_clock::now();
      selectPoints(*cloud, pager, camera, fovea, f + 1, selection);
      auto t1 = std::chrono::steady_clock::now();
      Result<std::size_t> loads = pager.update(selection.wanted, f + 1);
      if (!loads) return loads.status();
      auto t2 = std::chrono::steady_clock::now();
      frame.selectMs = milliseconds(t1 - t0);
      frame.pageMs = milliseconds(t2 - t1);
      frame.loads = *loads;
      frame.splats = selection.size();
      frame.inputPoints = selection.inputPoints;
      if (renderer) {
        const auto r0 = std::chrono::steady_clock::now();
        framebuffer->bind();
        renderer->upload(selection);
        renderer->draw(camera);
        context->finish();
        frame.renderMs = milliseconds(std::chrono::steady_clock::now() - r0);
      }
      frames.push_back(frame);
    }
    Frame mean;
    std::size_t maxSplats = 0, maxLoads = 0;
    for (const Frame& f : frames) {
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
    nlohmann::json run = {{"foveaRadius", radius},
                          {"fovealSplat", o.fovealSplat},
                          {"frames", nlohmann::json::array()}};
    for (const Frame& f : frames)
      run["frames"].push_back({{"splats", f.splats},
                               {"selectMs", f.selectMs},
                               {"pageMs", f.pageMs},
                               {"renderMs", f.renderMs},
                               {"loads", f.loads},
                               {"inputPoints", f.inputPoints}});
    json["runs"].push_back(std::move(run));
    all.insert(all.end(), frames.begin(), frames.end());
  }
  // The paper's §5 table: frame time by points used.
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
    for (const Frame& f : all) {
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
  if (!o.json.empty()) {
    Result<OutputFile> out = OutputFile::create(o.json);
    if (!out) return out.status();
    const std::string text = json.dump(2);
    LODFORGE_TRY(out->write(text.data(), text.size()));
    LODFORGE_TRY(out->commit());
  }
  return {};
}

Status runCloudView(const Global& global, const CloudRunOptions& o) {
  LODFORGE_TRY(claimIfGiven(o.screenshot, pngOutput(), {o.input}));
  Result<CloudFile> cloud = CloudFile::open(o.input);
  if (!cloud) return cloud.status();
  std::uint32_t width = 0, height = 0;
  LODFORGE_TRY(parseSize(o.size, width, height));
  auto gl = GlContext::window(width, height, "lodforge — " + o.input);
  if (!gl) return gl.status();
  GLFWwindow* window = (*gl)->glfwWindow();
  Result<PointRenderer> renderer = PointRenderer::create();
  if (!renderer) return renderer.status();

  const ImGuiPanel panel(window);

  const Aabbd bounds = cloud->header().bounds;
  std::vector<Camera> played;
  if (o.play) {
    Result<std::vector<Camera>> path = cloudPath(o, bounds);
    if (!path) return path.status();
    played = std::move(*path);
  }
  // Orbit around the centre: drag to turn, wheel to zoom; the fovea follows the mouse.
  double yaw = -std::numbers::pi / 2, pitch = 0.5;
  double distance = 1.2 * length(bounds.max - bounds.min);
  BlockPager pager(*cloud, o.residentBlocks, o.loadsPerFrame);
  FoveaOptions fovea;
  fovea.radius = o.foveaRadii.front();
  fovea.fovealSplat = o.fovealSplat;
  float radius = static_cast<float>(fovea.radius), splat = static_cast<float>(fovea.fovealSplat);
  PointSelection selection;
  double lastX = 0, lastY = 0, selectMs = 0, drawMs = 0;
  std::size_t loadsLastFrame = 0;
  glfwGetCursorPos(window, &lastX, &lastY);
  std::uint64_t frame = 0;
  while (!glfwWindowShouldClose(window)) {
    ++frame;
    glfwPollEvents();
    int fbWidth = 0, fbHeight = 0, winWidth = 0, winHeight = 0;
    glfwGetFramebufferSize(window, &fbWidth, &fbHeight);
    glfwGetWindowSize(window, &winWidth, &winHeight);
    double x = 0, y = 0;
    glfwGetCursorPos(window, &x, &y);
    const ImGuiIO& io = ImGui::GetIO();
    if (!io.WantCaptureMouse) {
      if (glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
        yaw -= (x - lastX) * 0.005;
        pitch = std::clamp(pitch + (y - lastY) * 0.005, -1.5, 1.5);
      }
      distance *= std::pow(0.9, io.MouseWheel);
    }
    lastX = x;
    lastY = y;
    const Vec3d forward{std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                        -std::sin(pitch)};
    const Vec3d eye = bounds.center() - forward * distance;
    Camera camera = Camera::lookAt(eye, bounds.center(), {0, 0, 1}, o.fovY,
                                   static_cast<std::uint32_t>(std::max(1, fbWidth)),
                                   static_cast<std::uint32_t>(std::max(1, fbHeight)));
    fitClipPlanes(camera, bounds);
    if (!played.empty()) {
      camera = played[(frame - 1) % played.size()];
      camera.width = static_cast<std::uint32_t>(std::max(1, fbWidth));
      camera.height = static_cast<std::uint32_t>(std::max(1, fbHeight));
    }
    // The gaze is the mouse, in framebuffer pixels (window and framebuffer may differ).
    const double scale = winWidth > 0 ? static_cast<double>(fbWidth) / winWidth : 1;
    fovea.gazeX = o.play ? -1 : x * scale;
    fovea.gazeY = o.play ? -1 : y * scale;
    fovea.radius = radius;
    fovea.fovealSplat = splat;
    const auto t0 = std::chrono::steady_clock::now();
    selectPoints(*cloud, pager, camera, fovea, frame, selection);
    Result<std::size_t> loads = pager.update(selection.wanted, frame);
    if (!loads) return loads.status();
    loadsLastFrame = *loads;
    const auto t1 = std::chrono::steady_clock::now();
    bindWindowFramebuffer();
    renderer->upload(selection);
    renderer->draw(camera);
    const auto t2 = std::chrono::steady_clock::now();
    selectMs = milliseconds(t1 - t0);
    drawMs = milliseconds(t2 - t1);

    const bool last = o.stopAfter > 0 && frame >= o.stopAfter;
    if (last && !o.screenshot.empty()) {
      (*gl)->finish();
      LODFORGE_TRY(writePng(o.screenshot, readPixels(0, camera.width, camera.height)));
    }
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
    ImGui::Begin("lodforge points");
    ImGui::Text("%s: %s points, %s blocks", o.input.c_str(),
                formatCount(cloud->header().pointCount).c_str(),
                formatCount(cloud->header().blockCount).c_str());
    ImGui::SliderFloat("fovea radius (px)", &radius, 10.0f, 2000.0f, "%.0f",
                       ImGuiSliderFlags_Logarithmic);
    ImGui::SliderFloat("foveal splat (px)", &splat, 0.5f, 32.0f, "%.1f",
                       ImGuiSliderFlags_Logarithmic);
    ImGui::Text("splats %s (standing for %s points)", formatCount(selection.size()).c_str(),
                formatCount(selection.inputPoints).c_str());
    ImGui::Text("blocks: %u visible, %u refined, %zu resident of %zu, %zu loaded this frame",
                selection.visibleBlocks, selection.refinedBlocks, pager.residentCount(),
                o.residentBlocks, loadsLastFrame);
    ImGui::Text("select + page %6.2f ms, draw %6.2f ms", selectMs, drawMs);
    ImGui::Text("drag: turn, wheel: zoom, the fovea follows the mouse");
    ImGui::End();
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glfwSwapBuffers(window);
    if (last) break;
  }
  say(global, fmt::format("{} frames shown, {} block loads", frame, pager.loads()));
  return {};
}

}  // namespace lodforge::cli
