#include "lodforge/io/cad/cad_reader.h"

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>

#include <fmt/format.h>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/cad/cad_module.h"
#include "lodforge/io/cad/step_names.h"
#include "lodforge/io/part21.h"

namespace lodforge {
namespace {

// Where the module is looked for: $LODFORGE_CAD_MODULE, beside the running program, then where
// the build put it.
std::vector<std::string> modulePlaces() {
  std::vector<std::string> places;
  if (const char* given = std::getenv("LODFORGE_CAD_MODULE")) places.emplace_back(given);
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) places.push_back((self.parent_path() / "liblodforge_cad.so").string());
  places.emplace_back(LODFORGE_CAD_MODULE_PATH);
  return places;
}

// The module, loaded once (never unloaded: OCCT keeps process-wide state); null, with `why`,
// when it cannot be.
void* loadedModule(std::string& why) {
  static std::once_flag once;
  static void* module = nullptr;
  static std::string reason;
  std::call_once(once, [] {
    for (const std::string& place : modulePlaces()) {
      // The error_code overload: a place that cannot be looked at (a name too long, a loop of
      // links) is a reason to report, not an exception out of the reader.
      std::error_code error;
      const bool there = std::filesystem::exists(place, error);
      if (error) reason = fmt::format("{}: cannot look for it: {}", place, error.message());
      if (!there) continue;
      module = dlopen(place.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (module) return;
      reason = dlerror();
    }
    if (reason.empty())
      reason = fmt::format("liblodforge_cad.so is in none of {}", fmt::join(modulePlaces(), ", "));
  });
  why = reason;
  return module;
}

// The module's plain arrays as a Model, relative to an origin near the parts.
Model toModel(const cad::Result& read) {
  Model model;
  Aabbd world;
  for (std::size_t v = 0; v < read.positions.size(); v += 3)
    world.add(Vec3d{read.positions[v], read.positions[v + 1], read.positions[v + 2]});
  model.origin = chooseOrigin(world);
  // One object per instance through ModelBuilder (offsets, names, bounds); the module wrote the
  // instances back to back, so appending them in order copies its arrays.
  for (const cad::Material& m : read.materials) {
    Material material;
    material.name = m.name;
    std::copy(m.baseColor, m.baseColor + 4, material.baseColor.begin());
    material.metallic = m.metallic;
    material.roughness = m.roughness;
    material.alphaMode = m.alphaMode == 2   ? AlphaMode::kBlend
                         : m.alphaMode == 1 ? AlphaMode::kMask
                                            : AlphaMode::kOpaque;
    material.alphaCutoff = m.alphaCutoff;
    material.doubleSided = m.doubleSided;
    std::copy(m.emissive, m.emissive + 3, material.emissive.begin());
    model.materials.push_back(std::move(material));
  }
  ModelBuilder builder(model);
  LayerTable layers(model.layers);
  for (const cad::Instance& instance : read.instances) {
    builder.beginObject(instance.name, instance.path);
    if (instance.material < model.materials.size())
      model.objects.back().material = instance.material;
    model.objects.back().layer = layers.index(instance.layer);
    for (std::uint64_t v = instance.firstVertex; v < instance.firstVertex + instance.vertexCount;
         ++v) {
      const double* p = &read.positions[3 * v];
      model.positions.push_back(toFloat(Vec3d{p[0], p[1], p[2]} - model.origin));
      model.normals.push_back(
          {read.normals[3 * v], read.normals[3 * v + 1], read.normals[3 * v + 2]});
      if (read.coloured)
        model.colors.push_back({read.colors[4 * v], read.colors[4 * v + 1], read.colors[4 * v + 2],
                                read.colors[4 * v + 3]});
    }
    const auto first =
        read.indices.begin() + static_cast<std::ptrdiff_t>(3 * instance.firstTriangle);
    model.indices.insert(model.indices.end(), first,
                         first + static_cast<std::ptrdiff_t>(3 * instance.triangleCount));
    builder.endObject();
  }
  return model;
}

// The code page of a STEP file whose names are not UTF-8 (none given): the one their bytes make
// clear, else UTF-8 with a warning that names --code-page. Empty: UTF-8.
Result<std::string> codePageOf(const std::string& path, std::vector<std::string>* warnings) {
  Result<StepStrings> strings = scanStepStrings(path);
  if (!strings) return strings.status();
  if (strings->notUtf8 == 0) return std::string();
  if (warnings && !strings->guess.empty())
    warnings->push_back(fmt::format(
        "{}: {} of its names are not UTF-8 (e.g. '{}'): read as {}, which their bytes suggest; "
        "--code-page gives another",
        path, strings->notUtf8, strings->example, strings->guess));
  if (warnings && strings->guess.empty())
    warnings->push_back(fmt::format(
        "{}: {} of its names are not UTF-8 (e.g. '{}') and show garbled: give the file's code "
        "page with --code-page (e.g. CP1251, CP1252, SJIS, GB)",
        path, strings->notUtf8, strings->example));
  return strings->guess;
}

// A damaged file's losses: the count and the first entities, or (`each`) every one with OCCT's
// reason. The shapes read stand without them, so the model is incomplete: said, not hidden.
void warnLost(const std::string& path, const std::vector<std::string>& lost, bool each,
              std::vector<std::string>& warnings) {
  if (lost.empty()) return;
  if (each) {
    for (const std::string& entity : lost)
      warnings.push_back(fmt::format("{}: OCCT could not read {}", path, entity));
    return;
  }
  std::string first;
  for (std::size_t i = 0; i < std::min<std::size_t>(lost.size(), 5); ++i)
    first += (i > 0 ? ", " : "") + lost[i].substr(0, lost[i].find(':'));
  warnings.push_back(fmt::format(
      "{}: damaged: OCCT could not read or transfer {} entit{} ({}{}); "
      "the model lacks what they held (-v lists them with OCCT's "
      "reasons)",
      path, lost.size(), lost.size() == 1 ? "y" : "ies", first, lost.size() > 5 ? ", …" : ""));
}

}  // namespace

Status cadModuleSymbol(const char* symbol, void*& entry) {
  std::string why;
  if (void* module = loadedModule(why)) {
    entry = dlsym(module, symbol);
    if (entry) return {};
    why = fmt::format("it has no {}", symbol);
  }
  return Error{ErrorKind::kUnsupported,
               fmt::format("this lodforge cannot read or write CAD files: its OpenCASCADE module "
                           "did not load ({})",
                           why)};
}

bool isCadPath(const std::string& path) {
  const std::string ext = fileExtension(path);
  return ext == "step" || ext == "stp" || ext == "iges" || ext == "igs" || ext == "brep" ||
         ext == "brp";
}

Result<Model> readCad(const std::string& path, const CadReadOptions& options,
                      std::vector<std::string>* warnings, CadReadStats* stats) {
  if (!(options.deflection > 0) || !std::isfinite(options.deflection))
    return Error{ErrorKind::kUsage, "--deflection must be a positive number"};
  if (!(options.angleDegrees > 0 && options.angleDegrees < 90))
    return Error{ErrorKind::kUsage, "--angle must lie between 0 and 90 degrees"};
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    return ioError(path, "cannot open: no such file");
  std::string codePage = options.codePage;
  if (const std::string ext = fileExtension(path); ext == "step" || ext == "stp") {
    LODFORGE_TRY(checkPart21Whole(path, options.salvageTruncated, warnings));
    if (codePage.empty()) {
      Result<std::string> page = codePageOf(path, warnings);
      if (!page) return page.status();
      codePage = *page;
    }
  }
  void* entry = nullptr;
  LODFORGE_TRY(cadModuleSymbol(cad::kReadSymbol, entry));
  const auto module = reinterpret_cast<cad::ReadFunction>(entry);
  const cad::Request request{.path = path,
                             .deflection = options.deflection,
                             .absoluteDeflection = options.absoluteDeflection,
                             .angleDegrees = options.angleDegrees,
                             .codePage = codePage,
                             .hidden = options.hidden};
  cad::Result read;
  module(cad::kModuleVersion, request, read);
  if (warnings) {
    warnLost(path, read.lost, options.listLost, *warnings);
    for (const std::string& w : read.warnings) warnings->push_back(fmt::format("{}: {}", path, w));
    if (read.hidden > 0 && read.status == 0)
      warnings->push_back(fmt::format(
          "{}: {} part(s) the file hides left out (--hidden keeps them)", path, read.hidden));
  }
  if (read.status == 2) return Error{ErrorKind::kUsage, read.error};
  if (read.status == 3) return Error{ErrorKind::kCancelled, "cancelled"};
  if (read.status != 0) return badInput(path, read.error);
  for (const cad::Instance& instance : read.instances)
    if (instance.vertexCount > std::numeric_limits<std::uint32_t>::max())
      return Error{ErrorKind::kUnsupported,
                   fmt::format("{}: part \"{}\" has more than 4G vertices at this deflection", path,
                               instance.name)};
  if (stats) *stats = {read.shapes, read.instances.size(), read.depth, read.hidden};
  return toModel(read);
}

}  // namespace lodforge
