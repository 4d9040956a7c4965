// `lodforge generate cad|scan|points`: deterministic synthetic inputs of any size, streamed to
// disk (see src/lodforge/generate/); `points --from MESH` samples a given mesh's surface.
#include <chrono>

#include <fmt/format.h>

#include "cli.h"
#include "lodforge/core/file.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/units.h"
#include "lodforge/generate/cad.h"
#include "lodforge/generate/points.h"
#include "lodforge/generate/scan.h"
#include "lodforge/generate/surface_samples.h"
#include "lodforge/io/model_io.h"
#include "outputs.h"

namespace lodforge::cli {

namespace {

void report(const Global& global, const std::string& path, const Result<GenerateStats>& stats,
            double seconds) {
  std::string counts =
      stats->triangles == 0 && stats->vertices == 0
          ? fmt::format("{} parts as B-rep", formatCount(stats->objects))
      : stats->triangles > 0
          ? fmt::format("{} objects, {} vertices, {} triangles", formatCount(stats->objects),
                        formatCount(stats->vertices), formatCount(stats->triangles))
          : fmt::format("{} points", formatCount(stats->vertices));
  say(global, fmt::format("wrote {}: {}, {} in {:.1f} s", path, counts, formatBytes(stats->bytes),
                          seconds));
  detail(global, fmt::format("peak memory {}", formatBytes(peakRssBytes())));
}

template <class Generate>
Status timed(const Global& global, const std::string& path, Generate&& generate,
             const std::vector<std::string>& inputs = {}) {
  LODFORGE_TRY(claimOutput(path, modelFileOutput(path), inputs));
  const auto start = std::chrono::steady_clock::now();
  Result<GenerateStats> stats = generate();
  if (!stats) return stats.status();
  report(global, path, stats,
         std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return {};
}

void addGenerateCad(CLI::App* generate, const Global& global, Run& run) {
  struct Options {
    CadOptions cad;
    std::string output;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = generate->add_subcommand(
      "cad", "A CAD-like assembly of many parts (GLB or PLY with object ids)");
  addCountOption(*sub, "--objects", options->cad.objects, "Number of parts (default 10K)");
  sub->add_option("--seed", options->cad.seed, "Random seed (same seed, same file)");
  sub->add_option("--detail", options->cad.detail, "Tessellation density factor (default 1)")
      ->check(CLI::PositiveNumber);
  sub->add_option(
      "-o,--output", options->output,
      "Output .glb, .ply or .step (B-rep through OpenCASCADE; default cad.glb, cad.ply above "
      "100K parts)");
  sub->callback([&global, &run, options] {
    if (options->output.empty())
      options->output = options->cad.objects > 100'000 ? "cad.ply" : "cad.glb";
    run = [&global, options] {
      return timed(global, options->output,
                   [&] { return generateCad(options->cad, options->output); });
    };
  });
}

void addGenerateScan(CLI::App* generate, const Global& global, Run& run) {
  struct Options {
    ScanOptions scan;
    std::string output = "scan.ply";
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub =
      generate->add_subcommand("scan", "One connected scanned surface of N triangles (PLY)");
  addCountOption(*sub, "--triangles", options->scan.triangles, "Number of triangles (default 1M)");
  sub->add_option("--seed", options->scan.seed, "Random seed");
  sub->add_option("--texture", options->scan.textureSize,
                  "Texture atlases of this many texels a side instead of vertex colours: 1K, "
                  "4K, 8K or a number (photo-like JPEGs beside the PLY, named in its "
                  "TextureFile comments)")
      ->transform(CLI::Transformer(
          {{"1K", "1024"}, {"2K", "2048"}, {"4K", "4096"}, {"8K", "8192"}, {"16K", "16384"}},
          CLI::ignore_case))
      ->check(CLI::Range(16u, 16384u));
  sub->add_option("--atlases", options->scan.atlases,
                  "With --texture: how many atlases over the scan (default 16)")
      ->check(CLI::Range(1u, 1024u));
  sub->add_option("-o,--output", options->output, "Output .ply (default scan.ply)");
  sub->callback([&global, &run, options] {
    run = [&global, options] {
      return timed(global, options->output,
                   [&] { return generateScan(options->scan, options->output); });
    };
  });
}

void addGeneratePoints(CLI::App* generate, const Global& global, Run& run) {
  struct Options {
    PointsOptions points;
    std::string output = "points.ply";
    std::string from;  // a mesh to sample instead of the terrain
    double noise = 0;  // with --from: a share of the mesh's bounding-box diagonal
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = generate->add_subcommand(
      "points", "A scanned-surface point cloud of N points (PLY, or LAS with lidar attributes)");
  addCountOption(*sub, "--points", options->points.points, "Number of points (default 1M)");
  sub->add_option("--seed", options->points.seed, "Random seed");
  sub->add_option("--from", options->from,
                  "Sample this mesh's surface by area instead (PLY with normals; its true surface "
                  "is known, for measuring reconstruct with compare)");
  sub->add_option("--noise", options->noise,
                  "With --from: Gaussian noise along the normal, standard deviation as a share "
                  "of the bounding-box diagonal (0.0005 = 0.05 %)");
  sub->add_option("-o,--output", options->output, "Output .ply or .las (default points.ply)");
  sub->add_flag("--extra-bytes", options->points.extraBytes,
                "LAS: add described extra bytes (height above ground, echo width, range, "
                "amplitude)");
  sub->callback([&global, &run, options] {
    run = [&global, options] {
      if (options->from.empty() && options->noise != 0)
        return Status(Error{ErrorKind::kUsage, "--noise goes with --from MESH"});
      if (options->from.empty())
        return timed(global, options->output,
                     [&] { return generatePoints(options->points, options->output); });
      if (options->points.extraBytes)
        return Status(Error{ErrorKind::kUsage,
                            "--extra-bytes goes with the terrain's LAS, "
                            "not --from"});
      if (fileExtension(options->output) != "ply")
        return Status(
            Error{ErrorKind::kUsage, fmt::format("{}: --from writes a .ply", options->output)});
      const auto sample = [&]() -> Result<GenerateStats> {
        Result<Model> model = readModel(options->from);
        if (!model) return model.status();
        return sampleSurface(*model, {options->points.points, options->points.seed, options->noise},
                             options->output);
      };
      return timed(global, options->output, sample, {options->from});
    };
  });
}

}  // namespace

void addGenerate(CLI::App& app, const Global& global, Run& run) {
  CLI::App* generate =
      app.add_subcommand("generate", "Write a synthetic model: cad, scan or points");
  generate->require_subcommand(1);
  addGenerateCad(generate, global, run);
  addGenerateScan(generate, global, run);
  addGeneratePoints(generate, global, run);
}

}  // namespace lodforge::cli
