// `lodforge convert IN -o OUT`: between the formats lodforge reads (.ply .obj .stl .gltf .glb)
// and writes (.ply .glb .obj .stl), optionally welding vertices or simplifying (textures kept,
// simplify_model.h) on the way; and LAZ (or LAS) to plain LAS, the point records as decoded.
#include <chrono>

#include <fmt/format.h>

#include "cad_options.h"
#include "cli.h"
#include "lodforge/core/file.h"
#include "lodforge/core/mesh.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/mesh/stl_writer.h"
#include "lodforge/io/model_io.h"
#include "lodforge/io/points/las_copy.h"
#include "lodforge/simplify/simplify_model.h"
#include "outputs.h"

namespace lodforge::cli {

namespace {

// Refuses before loading when the header already tells the model will not fit the limit.
Status checkMemory(const std::string& path, std::uint64_t limit) {
  if (limit == 0) return {};
  if (formatFromPath(path) != FileFormat::kPly)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: convert takes --memory-limit for PLY input only (its header "
                             "tells what loading needs); leave it out for this file",
                             path)};
  Result<PlyReader> reader = PlyReader::open(path);
  if (!reader) return reader.status();
  const PlyHeader& h = reader->header();
  const std::uint64_t need =
      modelMemoryBytes(h.vertexCount, h.faceCount, 1, h.hasNormals, h.hasColors);
  if (need <= limit) return {};
  return Error{ErrorKind::kLimit, fmt::format("{}: loading needs about {} but --memory-limit is {}",
                                              path, formatBytes(need), formatBytes(limit))};
}

bool isLasPath(const std::string& path) {
  const std::string ext = fileExtension(path);
  return ext == "las" || ext == "laz";
}

// What copying LAS takes at most: the program and one LAZ chunk decoded at a time (peak RSS
// 36 MiB on autzen_trim.laz, 50,000-point chunks; the rest is room for larger chunks).
constexpr std::uint64_t kLasCopyBytes = std::uint64_t{64} << 20;

// LAZ (or LAS) in, plain LAS out, streamed: within any --memory-limit from kLasCopyBytes up.
Status convertToLas(const Global& global, const std::string& input, const std::string& output) {
  const auto start = std::chrono::steady_clock::now();
  if (!isLasPath(input))
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: convert writes .las from .laz or .las input only", output)};
  if (global.memoryLimit > 0 && global.memoryLimit < kLasCopyBytes)
    return Error{ErrorKind::kLimit,
                 fmt::format("--memory-limit {} is too small to copy LAS points: at least {}",
                             formatBytes(global.memoryLimit), formatBytes(kLasCopyBytes))};
  LODFORGE_TRY(claimOutput(output, modelFileOutput(output), std::vector<std::string>{input}));
  Result<LasCopyReport> report = writeUncompressedLas(input, output);
  if (!report) return report.status();
  say(global,
      fmt::format("wrote {}: {} points, {} records kept{} in {:.2f} s", output,
                  formatCount(report->points), report->recordsKept,
                  report->recordsDropped > 0
                      ? fmt::format(", {} compression records dropped", report->recordsDropped)
                      : std::string{},
                  secondsSince(start)));
  return {};
}

struct ConvertOptions {
  std::string input, output;
  bool weld = false;
  float weldEpsilon = 0;
  bool stlAscii = false;
  bool salvage = false;
  double simplify = 1;
  CadCommand cad;
};

// What the output's extension asks for, before anything is read: a format convert writes, and
// an output it may claim.
Status checkModelOutput(const ConvertOptions& o) {
  if (!canWrite(formatFromPath(o.output)))
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: convert does not write {} (it writes .ply .glb .obj .stl "
                             "models, and .las from .las or .laz point clouds)",
                             o.output,
                             fileExtension(o.output) == "laz" ? std::string("LAZ (compressed LAS)")
                                                              : std::string("this format"))};
  LODFORGE_TRY(refusePointCloud(o.input, "convert"));
  return claimOutput(o.output, modelFileOutput(o.output), std::vector<std::string>{o.input});
}

// The input read (its warnings said), refused when it holds no triangle.
Result<Model> readConvertInput(const Global& global, const ConvertOptions& o) {
  LODFORGE_TRY(checkMemory(o.input, global.memoryLimit));
  Result<CadReadOptions> cad = cadOptions(o.cad, global);
  if (!cad) return cad.status();
  std::vector<std::string> warnings;
  Result<Model> model =
      readModel(o.input, {.salvageTruncated = o.salvage, .warnings = &warnings, .cad = *cad});
  for (const std::string& w : warnings) fmt::print(stderr, "lodforge: warning: {}\n", w);
  if (!model) return model.status();
  // As tiles and build: a model without triangles is nothing to convert (an empty file).
  if (model->triangleCount() == 0)
    return badInput(o.input, "the model has no triangles: nothing to convert");
  return model;
}

// --weld and --simplify, in that order.
void reshapeModel(const Global& global, const ConvertOptions& o, Model& model) {
  if (o.weld) {
    WeldOptions weld;
    weld.epsilon = o.weldEpsilon;
    weld.keepNormalSplits = model.hasNormals();
    weld.keepColorSplits = model.hasColors();
    weldModel(model, weld);
  }
  if (o.simplify < 1) {
    const ModelSimplifyStats stats = simplifyModel(model, o.simplify);
    say(global, fmt::format("simplified {} triangles to {} (error {:.4g} model units)",
                            formatCount(stats.trianglesBefore), formatCount(stats.trianglesAfter),
                            stats.error));
  }
}

Status writeConverted(const ConvertOptions& o, const Model& model) {
  if (formatFromPath(o.output) != FileFormat::kStl) return writeModel(model, o.output);
  if (!model.images.empty())
    fmt::print(stderr,
               "lodforge: warning: STL holds no textures: the {} image(s) of {} are left "
               "out (GLB, OBJ and PLY keep them)\n",
               model.images.size(), o.input);
  return writeStl(model, o.output, {o.stlAscii});
}

Status runConvert(const Global& global, const ConvertOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  if (fileExtension(o.output) == "las") return convertToLas(global, o.input, o.output);
  LODFORGE_TRY(checkModelOutput(o));
  Result<Model> model = readConvertInput(global, o);
  if (!model) return model.status();
  reshapeModel(global, o, *model);
  LODFORGE_TRY(writeConverted(o, *model));
  say(global, fmt::format("wrote {}: {} objects, {} vertices, {} triangles in {:.2f} s", o.output,
                          formatCount(model->objectCount()), formatCount(model->vertexCount()),
                          formatCount(model->triangleCount()), secondsSince(start)));
  return {};
}

}  // namespace

void addConvert(CLI::App& app, const Global& global, Run& run) {
  auto options = std::make_shared<ConvertOptions>();
  CLI::App* sub = app.add_subcommand("convert", "Convert a model between formats (by extension)");
  sub->add_option("INPUT", options->input,
                  "A .ply .obj .stl .gltf .glb model, a .step .iges .brep CAD file (or .laz/.las)")
      ->required();
  sub->add_option("-o,--output", options->output,
                  "A .ply .glb .obj or .stl file (or .las from .laz/.las)")
      ->required();
  sub->add_flag("--weld", options->weld,
                "Merge vertices with equal positions (keeping normal and colour splits)");
  sub->add_option("--weld-epsilon", options->weldEpsilon,
                  "With --weld: merge positions closer than this")
      ->check(CLI::NonNegativeNumber);
  sub->add_flag("--stl-ascii", options->stlAscii, "Write ascii STL instead of binary");
  sub->add_flag("--salvage", options->salvage,
                "Keep what a truncated PLY, STEP or IFC holds up to the cut (with a warning)");
  sub->add_option("--simplify", options->simplify,
                  "Keep this share of each object's triangles (0.1: a tenth), texture seams and "
                  "attribute splits kept")
      ->check(CLI::Range(0.0, 1.0));
  addCadOptions(*sub, options->cad);
  sub->callback([&global, &run, options] {
    run = [&global, options] { return runConvert(global, *options); };
  });
}

}  // namespace lodforge::cli
