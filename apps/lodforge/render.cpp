// `lodforge render model.lfp -o frames/`: headless PNG frames along a camera path, each frame
// selected under the budget (§4), streamed (§3.3) and drawn with OpenGL (EGL surfaceless, so it
// runs without a display or a GPU). `--reference` draws the full-detail model instead, for
// `lodforge compare`.
#include <chrono>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "lodforge/core/directory.h"
#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/render/context.h"
#include "lodforge/render/pipeline.h"
#include "lodforge/render/renderer.h"
#include "lodforge/runtime/selection.h"
#include "lodforge/runtime/stream.h"
#include "outputs.h"
#include "view_options.h"

namespace lodforge::cli {
namespace {

struct RenderOptions : PathChoice {
  std::string input, output;
  std::string budget = "10%";
  bool reference = false;
  bool firstPassOnly = false;
  double minT = 0.65;
  std::string color = "shaded";
  std::string json;
  bool gpuReform = false;
  bool gpuStream = false;  // §3.3 on the GPU: Δ upload, compute reassembly, GPU reformation

  RenderOptions() {
    frames = 8;
    path = "framed";  // pictures fill the frame; bench and view keep the fixed-radius orbit
  }
};

// The counts of the reference: every object at full detail.
void fullDetail(const Package& package, Selection& selection) {
  const std::size_t n = package.objectCount();
  selection.vertexCounts.resize(n);
  selection.triangleCounts.resize(n);
  selection.totalVertices = selection.totalTriangles = 0;
  for (std::size_t i = 0; i < n; ++i) {
    selection.vertexCounts[i] = package.object(i).vertexCount;
    selection.triangleCounts[i] = package.object(i).triangleCount;
    selection.totalVertices += selection.vertexCounts[i];
    selection.totalTriangles += selection.triangleCounts[i];
  }
}

// What one frame is drawn from, and what it draws with.
struct FrameView {
  const Camera& camera;
  std::uint64_t budget;
  ColorMode colorMode;
};
struct FrameTools {
  FramePipeline& pipeline;
  Framebuffer& target;
  Selection& selection;
};

// One frame: selected (or every object at full detail), streamed, drawn and written to `png`;
// its figures for render.json.
Result<nlohmann::json> renderFrame(const RenderOptions& o, const Package& package,
                                   const LodScene& scene, const FrameView& view,
                                   const FrameTools& tools, const std::string& png) {
  Selection& selection = tools.selection;
  const auto start = std::chrono::steady_clock::now();
  if (o.reference) {
    fullDetail(package, selection);
  } else {
    selectTwoPass(scene, view.camera, view.budget,
                  {.minT = o.minT, .firstPassOnly = o.firstPassOnly}, selection);
  }
  const auto selected = std::chrono::steady_clock::now();
  auto stream = tools.pipeline.update(selection.vertexCounts, selection.triangleCounts);
  if (!stream) return stream.status();
  tools.target.bind();
  tools.pipeline.draw(view.camera, {.colorMode = view.colorMode});
  const PipelineTimings& t = tools.pipeline.timings();
  LODFORGE_TRY(writePng(png, tools.target.read()));
  return nlohmann::json{{"vertices", selection.totalVertices},
                        {"triangles", selection.totalTriangles},
                        {"selection_ms", milliseconds(selected - start)},
                        {"generation_ms", t.streamMs + t.reformMs},
                        {"upload_ms", t.uploadMs},
                        {"render_ms", t.drawMs},
                        {"bytes_read", stream->bytesRead}};
}

Status runRender(const Global& global, const RenderOptions& o) {
  const std::vector<std::string> inputs{o.input};
  LODFORGE_TRY(claimOutput(o.output, renderFolderOutput(), inputs));
  if (!o.json.empty()) LODFORGE_TRY(claimOutput(o.json, jsonOutput(), inputs));
  Result<Package> package = Package::open(o.input);
  if (!package) return package.status();
  auto colorMode = parseColorMode(o.color);
  if (!colorMode) return colorMode.status();
  auto cameras = cameraPath(o, *package);
  if (!cameras) return cameras.status();
  const LodScene scene = LodScene::fromPackage(*package);
  const std::uint64_t full = scene.totalMaxVertices();
  auto budget = parseBudget(o.budget, full);
  if (!budget) return budget.status();

  auto gl = GlContext::headless();
  if (!gl) return gl.status();
  const StreamCapacity capacity =
      StreamCapacity::forVertices(*package, o.reference ? full : *budget);
  const Streaming streaming = o.gpuStream   ? Streaming::kGpu
                              : o.gpuReform ? Streaming::kCpuGpuReform
                                            : Streaming::kCpu;
  auto pipeline = FramePipeline::create(*package, capacity, streaming);
  if (!pipeline) return pipeline.status();
  auto target = Framebuffer::create(cameras->front().width, cameras->front().height);
  if (!target) return target.status();

  // Frames go into a temporary folder beside the output, which replaces the output (an earlier
  // render, as claimed above) when all are written.
  ScopedDirectory staging(temporaryPathFor(o.output));
  const std::filesystem::path temporary(staging.path);
  std::error_code error;
  std::filesystem::create_directories(temporary, error);
  if (error) return ioError(staging.path, fmt::format("cannot create: {}", error.message()));

  say(global, fmt::format("{}: {} objects, {} vertices; {} frames at {} ({}), {} on {}", o.input,
                          formatCount(package->objectCount()), formatCount(full), cameras->size(),
                          o.size, o.reference ? "full detail" : "budget " + formatCount(*budget),
                          colorModeName(*colorMode), (*gl)->renderer()));
  Selection selection;
  nlohmann::json frames = nlohmann::json::array();
  Progress progress("frames", cameras->size());
  for (std::size_t f = 0; f < cameras->size(); ++f) {
    LODFORGE_TRY(checkCancelled());
    const std::string name = fmt::format("frame_{:04}.png", f);
    Result<nlohmann::json> frame =
        renderFrame(o, *package, scene, {(*cameras)[f], *budget, *colorMode},
                    {*pipeline, *target, selection}, (temporary / name).string());
    if (!frame) return frame.status();
    (*frame)["frame"] = name;
    frames.push_back(std::move(*frame));
    progress.advance(1);
  }
  progress.finish();
  const nlohmann::json report = {
      {"package", o.input},
      {"budget", o.reference ? full : *budget},
      {"reference", o.reference},
      {"mode", o.reference ? "full" : (o.firstPassOnly ? "first-pass" : "two-pass")},
      {"color", colorModeName(*colorMode)},
      {"renderer", (*gl)->renderer()},
      {"frames", frames}};
  const std::string text = report.dump(2) + "\n";
  LODFORGE_TRY(OutputFile::writeWhole((temporary / "render.json").string(), text));
  LODFORGE_TRY(replaceDirectory(staging, o.output));
  if (!o.json.empty()) LODFORGE_TRY(OutputFile::writeWhole(o.json, text));
  double drawMs = 0;
  for (const auto& frame : frames) drawMs += frame["render_ms"].get<double>();
  say(global, fmt::format("wrote {} frames to {} (mean draw {:.1f} ms)", frames.size(), o.output,
                          drawMs / static_cast<double>(std::max<std::size_t>(1, frames.size()))));
  return {};
}

}  // namespace

void addRender(CLI::App& app, const Global& global, Run& run) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* sub = app.add_subcommand(
      "render", "Headless PNG frames along a camera path, under a vertex budget");
  sub->add_option("PACKAGE", o->input, "A .lfp package")->required();
  sub->add_option("-o,--output", o->output, "Folder for frame_NNNN.png and render.json")
      ->required();
  sub->add_option("--path", o->path,
                  "framed (an orbit that fills the frame with the model), orbit (a fixed "
                  "radius), fly, or a camera path JSON file (docs/formats.md)")
      ->capture_default_str();
  sub->add_option("--frames", o->frames, "Frames along the path (a file's path is cut to this)")
      ->capture_default_str()
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1'000'000}));
  sub->add_option("--budget", o->budget, "Vertex budget N: a count (3M) or a share (10%)")
      ->capture_default_str();
  sub->add_flag("--reference", o->reference, "Draw the full-detail model (no budget)")
      ->excludes("--budget");
  sub->add_flag("--first-pass-only", o->firstPassOnly, "Eq. 2 and 3 only (no second pass)");
  sub->add_option("--min-t", o->minT, "Eq. 3's MinT")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--size", o->size, "Image WIDTHxHEIGHT in pixels")->capture_default_str();
  sub->add_option("--fov", o->fovY, "Vertical field of view, degrees")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 179.0));
  sub->add_option("--color", o->color, "shaded, object, lod (vc/p) or normal")
      ->capture_default_str();
  sub->add_option("--json", o->json, "Also write the per-frame figures here");
  sub->add_flag("--gpu-reform", o->gpuReform,
                "Re-form triangles in a compute shader (§3.2) instead of on the CPU");
  sub->add_flag("--gpu-stream", o->gpuStream,
                "Stream on the GPU (§3.3): upload only the Δ, reassemble and re-form there");
  sub->callback([&global, &run, o, sub] {
    o->sizeGiven = sub->count("--size") > 0;
    run = [&global, o] { return runRender(global, *o); };
  });
}

}  // namespace lodforge::cli
