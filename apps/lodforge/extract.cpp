// `lodforge extract model.lfp --ratio R -o out.glb`: every object at a uniform level of detail.
#include <fmt/format.h>

#include "cli.h"
#include "lodforge/core/units.h"
#include "lodforge/io/model_io.h"
#include "lodforge/simplify/extract.h"
#include "outputs.h"

namespace lodforge::cli {

void addExtract(CLI::App& app, const Global& global, Run& run) {
  struct Options {
    std::string input, output;
    std::optional<double> ratio, error;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("extract", "Write a package's objects at one level of detail");
  sub->add_option("PACKAGE", options->input, "A .lfp package")->required();
  sub->add_option("-o,--output", options->output, "A .glb .ply .obj or .stl file")->required();
  auto* ratio =
      sub->add_option("--ratio", options->ratio, "Keep this share of each object's vertices (0..1)")
          ->check(CLI::Range(0.0, 1.0));
  auto* error =
      sub->add_option("--error", options->error,
                      "Keep the fewest vertices whose error is at most this (model units)")
          ->check(CLI::NonNegativeNumber);
  ratio->excludes(error);
  sub->callback([&global, &run, options] {
    run = [&global, options]() -> Status {
      if (!canWrite(formatFromPath(options->output)))
        return Error{
            ErrorKind::kUsage,
            fmt::format("{}: cannot write this format (lodforge writes .ply .glb .obj .stl)",
                        options->output)};
      LODFORGE_TRY(claimOutput(options->output, modelFileOutput(options->output),
                               std::vector<std::string>{options->input}));
      Result<Package> package = Package::open(options->input);
      if (!package) return package.status();
      const std::vector<std::uint32_t> counts =
          options->error ? vertexCountsForError(*package, *options->error)
                         : vertexCountsForRatio(*package, options->ratio.value_or(1.0));
      const Model model = extractModel(*package, counts);
      LODFORGE_TRY(writeModel(model, options->output));
      say(global, fmt::format("wrote {}: {} objects, {} vertices, {} triangles ({:.1f}% of {})",
                              options->output, formatCount(model.objectCount()),
                              formatCount(model.vertexCount()), formatCount(model.triangleCount()),
                              100.0 * static_cast<double>(model.triangleCount()) /
                                  static_cast<double>(
                                      std::max<std::uint64_t>(1, package->header().triangleCount)),
                              formatCount(package->header().triangleCount)));
      return {};
    };
  });
}

}  // namespace lodforge::cli
