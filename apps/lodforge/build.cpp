// `lodforge build INPUT -o model.lfp`: progressive meshes for every object (CAD paper §3.1).
#include <fmt/format.h>

#include "cad_options.h"
#include "cli.h"
#include "lodforge/core/file.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/units.h"
#include "lodforge/simplify/builder.h"
#include "outputs.h"

namespace lodforge::cli {

void addBuild(CLI::App& app, const Global& global, Run& run) {
  struct Options {
    std::string input, output;
    std::string cost = "quadric";
    std::string direction = "cheaper";
    bool salvage = false, noInstances = false;
    CadCommand cad;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("build", "Build the progressive package (.lfp) of a model");
  sub->add_option("INPUT", options->input,
                  "A .ply .obj .stl .gltf .glb model or a .step .iges .brep CAD file")
      ->required();
  sub->add_option("-o,--output", options->output, "The package to write (.lfp)")->required();
  sub->add_option("--cost", options->cost,
                  "Collapse cost: quadric (Garland-Heckbert) or melax (the paper's)")
      ->check(CLI::IsMember({"quadric", "melax"}));
  sub->add_option("--direction", options->direction,
                  "Interior edges collapse the cheaper way, or as Eq. 1 says (paper: lower index "
                  "into higher)")
      ->check(CLI::IsMember({"cheaper", "paper"}));
  sub->add_flag("--salvage", options->salvage,
                "Keep what a truncated PLY, STEP or IFC holds up to the cut");
  sub->add_flag(
      "--no-instances", options->noInstances,
      "Simplify every object on its own, even one that repeats an earlier object's shape");
  addCadOptions(*sub, options->cad);
  sub->callback([&global, &run, options] {
    run = [&global, options]() -> Status {
      if (fileExtension(options->output) != "lfp")
        return Error{ErrorKind::kUsage,
                     fmt::format("{}: a package is written as .lfp", options->output)};
      LODFORGE_TRY(refusePointCloud(options->input, "build"));
      LODFORGE_TRY(
          claimOutput(options->output, packageOutput(), std::vector<std::string>{options->input}));
      BuildOptions build;
      build.progressive.cost =
          options->cost == "melax" ? CollapseCost::kMelax : CollapseCost::kQuadric;
      build.progressive.direction =
          options->direction == "paper" ? CollapseDirection::kPaper : CollapseDirection::kCheaper;
      build.memoryLimit = global.memoryLimit;
      build.read.salvageTruncated = options->salvage;
      build.placeRepeatedShapes = !options->noInstances;
      Result<CadReadOptions> cad = cadOptions(options->cad, global);
      if (!cad) return cad.status();
      build.read.cad = *cad;
      std::vector<std::string> warnings;
      build.read.warnings = &warnings;
      Result<BuildStats> stats = buildPackage(options->input, options->output, build);
      for (const std::string& w : warnings) fmt::print(stderr, "lodforge: warning: {}\n", w);
      if (!stats) return stats.status();
      // Placements only when there are some (never with --no-instances).
      const std::string placed = stats->placements == 0
                                     ? std::string()
                                     : fmt::format(" ({} placed again from an earlier one's shape)",
                                                   formatCount(stats->placements));
      say(global,
          fmt::format(
              "wrote {}: {} objects{}, {} vertices, {} triangles ({} at the simplest "
              "level), {} in {:.1f} s ({} input triangles/s)",
              options->output, formatCount(stats->objects), placed, formatCount(stats->vertices),
              formatCount(stats->triangles), formatCount(stats->minTriangles),
              formatBytes(stats->packageBytes), stats->seconds,
              formatCount(static_cast<std::uint64_t>(static_cast<double>(stats->inputTriangles) /
                                                     std::max(stats->seconds, 1e-9)))));
      detail(global, fmt::format("{}; {} waves; shapes kept to place again {}; peak memory {}",
                                 stats->streamed ? "streamed" : "loaded whole", stats->waves,
                                 formatBytes(stats->shapeCacheBytes), formatBytes(peakRssBytes())));
      return {};
    };
  });
}

}  // namespace lodforge::cli
