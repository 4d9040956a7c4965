// `lodforge bench model.lfp`: the CAD paper's Table 1 on the CPU. Along a camera path, every
// frame selects vertex counts under the budget (§4) and brings the stream buffer up to date
// (§3.3 reassembly, then Algorithm 2 reformation); per budget it prints the mean per-frame
// milliseconds of each stage, what was read and moved, and whether Σ vc hit the budget.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "cloud.h"
#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/threads.h"
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

struct BenchOptions : PathChoice {
  std::string input;
  std::string budgets = "1%,5%,20%";
  std::uint64_t gpuMemory = 0;
  bool firstPassOnly = false;
  double minT = 0.65;
  double exponent = 3.0;
  std::optional<double> targetError;
  std::string json;
  std::string recordPath;
  bool render = false;     // draw every frame headless (OpenGL; llvmpipe without a GPU)
  bool gpuReform = false;  // with --render: re-form in a compute shader
  bool gpuStream = false;  // with --render: stream on the GPU (§3.3), re-form there
};

Streaming streaming(const BenchOptions& o) {
  return o.gpuStream ? Streaming::kGpu : (o.gpuReform ? Streaming::kCpuGpuReform : Streaming::kCpu);
}

// What --render draws with: one headless context for the whole run.
struct RenderTarget {
  std::unique_ptr<GlContext> context;
  std::optional<Framebuffer> framebuffer;
};
struct FrameTimes {
  double selectionMs = 0;
  Selection::Timings selectionSteps;
  FrameStats stream;
  std::uint64_t vertices = 0, triangles = 0, visible = 0;
  bool exact = true;
  double uploadMs = 0;  // --render: buffers to the GL (and the GPU reformation)
  std::optional<std::uint64_t> uploadedBytes;  // --render, CPU stream: bytes copied to the GL
  double renderMs = 0;                         // --render: the draw, to glFinish
};

// A budget's run: the first frame (everything read) apart from the coherent frames after it.
struct BudgetRun {
  std::uint64_t budget = 0;  // 0 in error-driven mode
  std::uint64_t capacityVertices = 0, capacityBytes = 0;
  FrameTimes load;
  std::vector<FrameTimes> frames;
};

// One frame: select, then stream.
Result<FrameTimes> runFrame(const BenchOptions& o, const LodScene& scene, const Camera& camera,
                            std::uint64_t budget, Selection& selection, StreamBuffer* buffer,
                            RenderTarget* target, FramePipeline* pipeline) {
  FrameTimes t;
  const auto start = std::chrono::steady_clock::now();
  if (o.targetError) {
    selectByError(scene, camera, *o.targetError, selection);
  } else {
    selectTwoPass(scene, camera, budget,
                  {.exponent = o.exponent, .minT = o.minT, .firstPassOnly = o.firstPassOnly},
                  selection);
  }
  t.selectionMs = milliseconds(std::chrono::steady_clock::now() - start);
  t.selectionSteps = selection.timings;
  t.vertices = selection.totalVertices;
  t.triangles = selection.totalTriangles;
  t.visible = selection.visibleObjects;
  t.exact = o.targetError || o.firstPassOnly ||
            selection.totalVertices == std::min(budget, scene.totalMaxVertices());
  if (!pipeline) {
    auto stream = buffer->update(selection.vertexCounts, selection.triangleCounts);
    if (!stream) return stream.status();
    t.stream = *stream;
    return t;
  }
  // With --render, the paper's third column too: the frame drawn (offscreen, to glFinish).
  auto stream = pipeline->update(selection.vertexCounts, selection.triangleCounts);
  if (!stream) return stream.status();
  t.stream = *stream;
  target->framebuffer->bind();
  pipeline->draw(camera, {});
  const PipelineTimings& p = pipeline->timings();
  if (pipeline->streaming() == Streaming::kGpu) {
    // Generation is the GPU's: Δ upload and reassembly, then Algorithm 2.
    t.stream.reassemblyMs = p.streamMs;
    t.stream.reformationMs = p.reformMs;
  }
  t.uploadMs = p.uploadMs + (pipeline->streaming() == Streaming::kCpuGpuReform ? p.reformMs : 0);
  t.renderMs = p.drawMs;
  if (pipeline->streaming() != Streaming::kGpu) t.uploadedBytes = p.uploadedBytes;
  return t;
}

Result<BudgetRun> runBudget(const BenchOptions& o, const Package& package, const LodScene& scene,
                            const std::vector<Camera>& cameras, std::uint64_t budget,
                            Progress& progress, RenderTarget* target) {
  BudgetRun run;
  run.budget = budget;
  const std::uint64_t full = scene.totalMaxVertices();
  StreamCapacity capacity =
      o.gpuMemory ? StreamCapacity::forMemory(package, o.gpuMemory)
                  : StreamCapacity::forVertices(package, o.targetError ? full : budget);
  if (!o.targetError && std::min(budget, full) > capacity.vertices)
    return Error{
        ErrorKind::kUsage,
        fmt::format(
            "--budget {} does not fit --gpu-memory {}: it holds {} vertices of this package",
            formatCount(budget), formatBytes(o.gpuMemory), formatCount(capacity.vertices))};
  run.capacityVertices = capacity.vertices;
  run.capacityBytes = capacity.bytes(package);
  std::optional<StreamBuffer> buffer;  // without --render: the CPU stream alone
  std::optional<FramePipeline> pipeline;
  if (target) {
    auto created = FramePipeline::create(package, capacity, streaming(o));
    if (!created) return created.status();
    pipeline.emplace(std::move(*created));
  } else {
    buffer.emplace(package, capacity);
  }
  Selection selection;
  for (std::size_t f = 0; f < cameras.size(); ++f) {
    LODFORGE_TRY(checkCancelled());
    auto frame = runFrame(o, scene, cameras[f], budget, selection, buffer ? &*buffer : nullptr,
                          target, pipeline ? &*pipeline : nullptr);
    if (!frame) return frame.status();
    (f == 0 ? run.load : run.frames.emplace_back()) = *frame;
    progress.advance(1);
  }
  return run;
}

// Mean of a per-frame quantity over the coherent frames.
template <class F>
double mean(const std::vector<FrameTimes>& frames, F f) {
  if (frames.empty()) return 0;
  double sum = 0;
  for (const FrameTimes& t : frames) sum += static_cast<double>(f(t));
  return sum / static_cast<double>(frames.size());
}

template <class F>
double percentile95(const std::vector<FrameTimes>& frames, F f) {
  if (frames.empty()) return 0;
  std::vector<double> values;
  for (const FrameTimes& t : frames) values.push_back(static_cast<double>(f(t)));
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1,
                         static_cast<std::size_t>(0.95 * static_cast<double>(values.size())))];
}

double generationMs(const FrameTimes& t) {
  return t.stream.reassemblyMs + t.stream.reformationMs;
}

nlohmann::json frameJson(const FrameTimes& t) {
  return {{"selection_ms", t.selectionMs},
          {"reassembly_ms", t.stream.reassemblyMs},
          {"reformation_ms", t.stream.reformationMs},
          {"generation_ms", generationMs(t)},
          {"bytes_read", t.stream.bytesRead},
          {"bytes_moved", t.stream.bytesMoved},
          {"triangles_reformed", t.stream.trianglesReformed},
          {"triangles_kept", t.stream.trianglesKept},
          {"objects_changed", t.stream.objectsChanged},
          {"objects_relocated", t.stream.objectsRelocated},
          {"compacted", t.stream.compacted},
          {"vertices", t.vertices},
          {"triangles", t.triangles},
          {"visible_objects", t.visible},
          {"upload_ms", t.uploadMs},
          {"uploaded_bytes", t.uploadedBytes ? nlohmann::json(*t.uploadedBytes) : nullptr},
          {"render_ms", t.renderMs}};
}

nlohmann::json runJson(const BudgetRun& run) {
  nlohmann::json means = nlohmann::json::object();
  const auto add = [&](const char* name, auto f) { means[name] = mean(run.frames, f); };
  add("selection_ms", [](const FrameTimes& t) { return t.selectionMs; });
  add("importance_ms", [](const FrameTimes& t) { return t.selectionSteps.importance; });
  add("first_pass_ms", [](const FrameTimes& t) { return t.selectionSteps.firstPass; });
  add("second_pass_ms", [](const FrameTimes& t) { return t.selectionSteps.secondPass; });
  add("triangle_counts_ms", [](const FrameTimes& t) { return t.selectionSteps.finish; });
  add("reassembly_ms", [](const FrameTimes& t) { return t.stream.reassemblyMs; });
  add("reformation_ms", [](const FrameTimes& t) { return t.stream.reformationMs; });
  add("generation_ms", generationMs);
  add("bytes_read", [](const FrameTimes& t) { return t.stream.bytesRead; });
  add("bytes_moved", [](const FrameTimes& t) { return t.stream.bytesMoved; });
  add("triangles_reformed", [](const FrameTimes& t) { return t.stream.trianglesReformed; });
  add("triangles_kept", [](const FrameTimes& t) { return t.stream.trianglesKept; });
  add("objects_changed", [](const FrameTimes& t) { return t.stream.objectsChanged; });
  add("objects_relocated", [](const FrameTimes& t) { return t.stream.objectsRelocated; });
  add("vertices", [](const FrameTimes& t) { return t.vertices; });
  add("triangles", [](const FrameTimes& t) { return t.triangles; });
  add("visible_objects", [](const FrameTimes& t) { return t.visible; });
  add("upload_ms", [](const FrameTimes& t) { return t.uploadMs; });
  if (!run.frames.empty() && run.frames.front().uploadedBytes) {
    add("uploaded_bytes", [](const FrameTimes& t) { return t.uploadedBytes.value_or(0); });
  } else {
    means["uploaded_bytes"] = nullptr;  // not measured (no --render, or the GPU stream)
  }
  add("render_ms", [](const FrameTimes& t) { return t.renderMs; });
  const auto exactFrames = static_cast<std::uint64_t>(std::count_if(
      run.frames.begin(), run.frames.end(), [](const FrameTimes& t) { return t.exact; }));
  const auto compactedFrames = static_cast<std::uint64_t>(
      std::count_if(run.frames.begin(), run.frames.end(),
                    [](const FrameTimes& t) { return t.stream.compacted; }));
  return {{"budget", run.budget},
          {"capacity_vertices", run.capacityVertices},
          {"capacity_bytes", run.capacityBytes},
          {"load", frameJson(run.load)},
          {"frames", run.frames.size()},
          {"mean", means},
          {"triangles_per_second", 1e3 * means["triangles"].get<double>() /
                                       std::max(1e-9, means["selection_ms"].get<double>() +
                                                          means["generation_ms"].get<double>())},
          {"p95_selection_ms",
           percentile95(run.frames, [](const FrameTimes& t) { return t.selectionMs; })},
          {"p95_generation_ms", percentile95(run.frames, generationMs)},
          {"exact_frames", exactFrames + (run.load.exact ? 1 : 0)},
          {"compacted_frames", compactedFrames}};
}

std::string megabytes(double bytes) {
  return fmt::format("{:.1f}", bytes / 1e6);
}

// The table reads the same per-run summaries the JSON holds, so the two never disagree.
void printTable(const Global& global, const BenchOptions& o, const nlohmann::json& runs) {
  say(global,
      fmt::format(
          "{:>12} {:>9} | {:>9} {:>9} {:>9} | {:>8} {:>8} {:>8} {:>8} | {:>10} {:>9} {:>7} | {:>9} "
          "{:>9} | {:>6}",
          o.targetError ? "error px" : "budget N", "visible", "sel ms", "reasm ms", "reform ms",
          "gen ms", "gen p95", "read MB", "moved MB", "reformed", "Mtri/s", "load ms", "upload ms",
          "render ms", "Σ=N"));
  for (const nlohmann::json& r : runs) {
    const nlohmann::json& m = r["mean"];
    const auto number = [&](const char* key) { return m[key].get<double>(); };
    const auto count = [&](const char* key) {
      return formatCount(static_cast<std::uint64_t>(number(key)));
    };
    say(global,
        fmt::format(
            "{:>12} {:>9} | {:>9.2f} {:>9.2f} {:>9.2f} | {:>8.2f} {:>8.2f} {:>8} {:>8} | {:>10} "
            "{:>9.0f} {:>7.1f} | {:>9} {:>9} | {:>6}",
            o.targetError ? fmt::format("{:g}", *o.targetError)
                          : formatCount(r["budget"].get<std::uint64_t>()),
            count("visible_objects"), number("selection_ms"), number("reassembly_ms"),
            number("reformation_ms"), number("generation_ms"), r["p95_generation_ms"].get<double>(),
            megabytes(number("bytes_read")), megabytes(number("bytes_moved")),
            count("triangles_reformed"), r["triangles_per_second"].get<double>() / 1e6,
            r["load"]["selection_ms"].get<double>() + r["load"]["generation_ms"].get<double>(),
            o.render ? fmt::format("{:.2f}", number("upload_ms")) : std::string("-"),
            o.render ? fmt::format("{:.2f}", number("render_ms")) : std::string("-"),
            o.targetError || o.firstPassOnly
                ? std::string("-")
                : fmt::format("{}/{}", r["exact_frames"].get<std::uint64_t>(),
                              r["frames"].get<std::uint64_t>() + 1)));
    detail(global, fmt::format("  selection steps (ms): importance {:.2f}, first pass {:.2f}, "
                               "second pass {:.2f}, triangle counts {:.2f}",
                               number("importance_ms"), number("first_pass_ms"),
                               number("second_pass_ms"), number("triangle_counts_ms")));
  }
}

Status writeJson(const BenchOptions& o, const Package& package, const nlohmann::json& runsJson,
                 std::size_t frames) {
  const nlohmann::json document = {
      {"package", o.input},
      {"objects", package.objectCount()},
      {"vertices", package.header().vertexCount},
      {"triangles", package.header().triangleCount},
      {"threads", hardwareThreads()},
      {"path", o.path},
      {"frames", frames},
      {"mode", o.targetError ? "error" : (o.firstPassOnly ? "first-pass" : "two-pass")},
      {"render", o.render ? streamingName(streaming(o)) : "none"},
      {"min_t", o.minT},
      {"exponent", o.exponent},
      {"runs", runsJson}};
  const std::string text = document.dump(2);
  auto file = OutputFile::create(o.json);
  if (!file) return file.status();
  LODFORGE_TRY(file->write(text.data(), text.size()));
  return file->commit();
}

Status runBench(const Global& global, const BenchOptions& o) {
  LODFORGE_TRY(claimIfGiven(o.json, jsonOutput(), {o.input}));
  LODFORGE_TRY(claimIfGiven(o.recordPath, jsonOutput(), {o.input}));
  Result<Package> package = Package::open(o.input);
  if (!package) return package.status();
  const LodScene scene = LodScene::fromPackage(*package, o.exponent);
  auto cameras = cameraPath(o, *package);
  if (!cameras) return cameras.status();
  if (!o.recordPath.empty())
    LODFORGE_TRY(writeCameraPath(o.recordPath, *cameras, package->origin()));
  std::vector<std::uint64_t> budgets{0};
  if (!o.targetError) {
    auto parsed = parseBudgets(o.budgets, scene.totalMaxVertices());
    if (!parsed) return parsed.status();
    budgets = *parsed;
  }
  say(global,
      fmt::format("{}: {} objects, {} vertices, {} triangles; {} frames along {} at {}, {} threads",
                  o.input, formatCount(package->objectCount()),
                  formatCount(scene.totalMaxVertices()),
                  formatCount(package->header().triangleCount), cameras->size(), o.path, o.size,
                  hardwareThreads()));
  std::optional<RenderTarget> target;
  std::string rendererName;
  if (o.render) {
    auto context = GlContext::headless();
    if (!context) return context.status();
    auto framebuffer = Framebuffer::create(cameras->front().width, cameras->front().height);
    if (!framebuffer) return framebuffer.status();
    rendererName = (*context)->renderer();
    say(global, "rendering on " + rendererName + " (" + (*context)->platform() + ")");
    target.emplace(RenderTarget{std::move(*context), std::move(*framebuffer)});
  }
  nlohmann::json runs = nlohmann::json::array();
  Progress progress("frames", budgets.size() * cameras->size());
  for (const std::uint64_t budget : budgets) {
    auto run =
        runBudget(o, *package, scene, *cameras, budget, progress, target ? &*target : nullptr);
    if (!run) return run.status();
    runs.push_back(runJson(*run));
  }
  progress.finish();
  printTable(global, o, runs);
  if (!o.json.empty()) LODFORGE_TRY(writeJson(o, *package, runs, cameras->size()));
  return {};
}

}  // namespace

void addBench(CLI::App& app, const Global& global, Run& run) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* sub =
      app.add_subcommand("bench", "Time LOD selection and coherent streaming along a camera path");
  sub->add_option("PACKAGE", o->input, "A .lfp package or a .lfc point package")->required();
  sub->add_option("--path", o->path, "orbit, fly, or a camera path JSON file (docs/formats.md)")
      ->capture_default_str();
  sub->add_option("--frames", o->frames, "Frames along the path (a file's path is cut to this)")
      ->capture_default_str()
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1'000'000}));
  sub->add_option(
         "--budget", o->budgets,
         "Budgets N in vertices, comma-separated: counts (3M, 10.5M) or shares of the model (5%)")
      ->capture_default_str();
  addByteSizeOption(
      *sub, "--gpu-memory", o->gpuMemory,
      "Size the stream buffer (both copies) from this many bytes instead of the budget");
  sub->add_option("--size", o->size, "Viewport WIDTHxHEIGHT in pixels")->capture_default_str();
  sub->add_option("--fov", o->fovY, "Vertical field of view, degrees")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 179.0));
  sub->add_flag("--first-pass-only", o->firstPassOnly,
                "Eq. 2 and 3 only (no second pass; Σ is not N)");
  sub->add_option("--min-t", o->minT, "Eq. 3's MinT")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--exponent", o->exponent, "Eq. 2's 1/α")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 8.0));
  auto* error =
      sub->add_option("--target-error", o->targetError,
                      "Error-driven instead of budgeted: projected error at most this many pixels")
          ->check(CLI::PositiveNumber);
  error->excludes("--first-pass-only");
  sub->add_option("--json", o->json, "Also write the results as JSON");
  sub->add_option("--record-path", o->recordPath, "Write the cameras used as a path JSON file");
  sub->add_flag("--render", o->render,
                "Also draw every frame headless (OpenGL 4.5; on llvmpipe these are CPU times)");
  sub->add_flag("--gpu-reform", o->gpuReform, "With --render: re-form in a compute shader")
      ->needs("--render");
  sub->add_flag("--gpu-stream", o->gpuStream,
                "With --render: stream on the GPU as the paper does (only the Δ is uploaded; "
                "reassembly and reformation in compute shaders)")
      ->needs("--render");
  // Point packages (.lfc): the points paper's runtime instead.
  auto cloud = std::make_shared<CloudRunOptions>();
  addCloudOptions(*sub, *cloud, /*severalRadii=*/true);
  sub->callback([&global, &run, o, sub, cloud] {
    o->sizeGiven = sub->count("--size") > 0;
    if (fileExtension(o->input) == "lfc") {
      takePackageRun(*cloud, o->input, *o);
      cloud->render = o->render;
      cloud->json = o->json;
      run = [&global, cloud] { return runCloudBench(global, *cloud); };
      return;
    }
    run = [&global, o] { return runBench(global, *o); };
  });
}

}  // namespace lodforge::cli
