// `lodforge points INPUT -o cloud.lfc`: a point cloud (LAS, PLY, XYZ/TXT/CSV/PTS) as a point
// package with error-controlled LODs per block (points paper §4.1).
#include <filesystem>

#include <fmt/format.h>

#include "cli.h"
#include "lodforge/core/file.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/units.h"
#include "lodforge/points/build.h"

namespace lodforge::cli {

void addPoints(CLI::App& app, const Global& global, Run& run) {
  struct Options {
    std::string input, output;
    std::uint64_t blockSize = 50'000;
    double tolerance = 0;
    double residentShare = 1.0 / 32;
    int neighbours = 12;
    bool salvage = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "points", "Build a point package (.lfc): blocks, clustering LODs, segment files");
  sub->add_option("INPUT", options->input, "A .las .laz .ply .xyz .txt .csv or .pts point cloud")
      ->required();
  sub->add_option("-o,--output", options->output,
                  "The .lfc package to write (segment files go "
                  "to the .lfs directory beside it)")
      ->required();
  addCountOption(*sub, "--block-size", options->blockSize, "Most points per block (default 50K)");
  sub->add_option("--tolerance", options->tolerance,
                  "Error tolerance (metres) that cuts each block's tree into Part II (memory) "
                  "and Part III (segment file); default: the one that keeps --resident-share")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--resident-share", options->residentShare,
                  "Without --tolerance: Part II nodes per input point (default 1/32)")
      ->check(CLI::Range(1e-6, 1.0));
  sub->add_option("--neighbours", options->neighbours,
                  "Neighbours for normals where the input has none (default 12)")
      ->check(CLI::Range(3, 64));
  sub->add_flag("--salvage", options->salvage,
                "Read a PLY cut short up to its last whole point (with a warning)");
  sub->callback([&global, &run, options] {
    run = [&global, options]() -> Status {
      if (fileExtension(options->output) != "lfc")
        return Error{ErrorKind::kUsage,
                     fmt::format("{}: the output should end in .lfc", options->output)};
      PointsBuildOptions build;
      build.blockSize = std::max<std::uint64_t>(1, options->blockSize);
      build.tolerance = options->tolerance;
      build.residentShare = options->residentShare;
      build.cluster.neighbours = options->neighbours;
      build.memoryLimit = global.memoryLimit;
      build.salvageTruncated = options->salvage;
      Result<PointsBuildStats> stats = buildPointCloud(options->input, options->output, build);
      if (!stats) return stats.status();
      if (stats->truncation)
        fmt::print(stderr, "lodforge: warning: {}; built from what came before\n",
                   *stats->truncation);
      for (const std::string& warning : stats->warnings)
        fmt::print(stderr, "lodforge: warning: {}\n", warning);
      say(global,
          fmt::format("wrote {}: {} points in {} blocks, Part II {} nodes, Part III {}, {} in "
                      "{:.1f} s ({} points/s)",
                      options->output, formatCount(stats->points), formatCount(stats->blocks),
                      formatCount(stats->residentNodes), formatCount(stats->segmentNodes),
                      formatBytes(stats->outputBytes), stats->seconds,
                      formatCount(static_cast<std::uint64_t>(static_cast<double>(stats->points) /
                                                             std::max(stats->seconds, 1e-9)))));
      detail(
          global,
          fmt::format(
              "tolerance {:.6g}; {} threads; blocks of {} to {} points; {} streamed split passes; "
              "{:.1f} s to partition; normals {}; Part I {} nodes dropped; peak "
              "memory {}",
              stats->tolerance, stats->threads, formatCount(stats->minBlock),
              formatCount(stats->maxBlock), stats->streamedPasses, stats->partitionSeconds,
              stats->estimatedNormals ? "estimated" : "from the input",
              formatCount(stats->droppedNodes), formatBytes(peakRssBytes())));
      return {};
    };
  });
}

}  // namespace lodforge::cli
