// `lodforge reconstruct CLOUD -o mesh.ply`: a surface from a point cloud, chunk by chunk
// (large-meshes paper §3.1, §3.3; docs/surface.md).
#include <algorithm>
#include <chrono>
#include <filesystem>

#include <fmt/format.h>

#include "cli.h"
#include "lodforge/core/cluster.h"
#include "lodforge/core/file.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/output_claim.h"
#include "lodforge/core/units.h"
#include "lodforge/io/points/point_reader.h"
#include "lodforge/surface/reconstruct.h"
#include "lodforge/surface/resume_state.h"
#include "outputs.h"
#include "surface_options.h"

namespace lodforge::cli {

namespace {

// -v for a job of several ranks: the chunks each made, and when each step was done.
void reportRanks(const Global& global, const ReconstructStats& stats) {
  const auto [least, most] = std::minmax_element(stats.rankChunks.begin(), stats.rankChunks.end());
  const auto [first, last] =
      std::minmax_element(stats.rankMadeSeconds.begin(), stats.rankMadeSeconds.end());
  detail(global, fmt::format("{} ranks: the points sorted into runs by rank 0 (done at {:.1f} s); "
                             "the runs made by the ranks, {} to {} chunks a rank (each done at "
                             "{:.1f} to {:.1f} s); joined by rank 0 (done at {:.1f} s)",
                             stats.rankChunks.size(), stats.sortedSeconds, formatCount(*least),
                             formatCount(*most), *first, *last, stats.joinedSeconds));
  for (const std::string& line : stats.rankStages) detail(global, line);
}

struct ReconstructCommand {
  std::string input, output;
  SurfaceCommand surface;
  bool salvage = false;
  bool resume = false;
};

// The command once parsed: the surface written, or why not.
Status runReconstruct(const Global& global, const ReconstructCommand& options) {
  const auto start = std::chrono::steady_clock::now();
  if (fileExtension(options.output) != "ply")
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: reconstruct writes a .ply mesh", options.output)};
  if (!isPointCloudPath(options.input) && fileExtension(options.input) != "ply")
    return Error{
        ErrorKind::kUsage,
        fmt::format("{}: not a point cloud (.las .laz .ply .xyz .txt .csv .pts)", options.input)};
  Result<ReconstructOptions> reconstruct = surfaceOptions(options.surface, options.input);
  if (!reconstruct) return reconstruct.status();
  // In a job, rank 0 claims the output for all (docs/distributed.md).
  LODFORGE_TRY(agreeAcrossRanks(clusterRank() != 0
                                    ? Status{}
                                    : claimOutput(options.output, modelFileOutput(options.output),
                                                  std::vector<std::string>{options.input})));
  reconstruct->memoryLimit = global.memoryLimit;
  reconstruct->salvageTruncated = options.salvage;
  reconstruct->resumable = true;
  reconstruct->resume = options.resume;
  reconstruct->acrossRanks = clustered();
  Result<ReconstructStats> mesh = reconstructToFile(options.input, options.output, *reconstruct);
  if (!mesh) {
    std::error_code ignored;
    const std::string work = reconstructWorkDirectory(options.output);
    // Not where another run holds the work (this one was refused), and once for a job.
    if (clusterRank() == 0 && std::filesystem::exists(reconstructStatePath(work), ignored) &&
        !workDirectoryLocked(work))
      fmt::print(stderr,
                 "lodforge: the finished runs of chunks are kept in {}: run again with "
                 "--resume to continue, or delete it\n",
                 work);
    return mesh.status();
  }
  for (const std::string& warning : mesh->warnings)
    fmt::print(stderr, "lodforge: warning: {}\n", warning);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  say(global,
      fmt::format("wrote {}: {} triangles, {} vertices from {} points in {:.2f} s "
                  "(voxel {:g}, {} chunks in {} run{}{}{}{})",
                  options.output, formatCount(mesh->triangles), formatCount(mesh->vertices),
                  formatCount(mesh->points), seconds, mesh->grid.voxel, formatCount(mesh->chunks),
                  mesh->runs, mesh->runs == 1 ? "" : "s",
                  mesh->resumedRuns > 0 ? fmt::format(", {} resumed", mesh->resumedRuns) : "",
                  mesh->estimatedNormals ? ", normals estimated" : "",
                  mesh->droppedPieces > 0
                      ? fmt::format(", {} small pieces dropped", mesh->droppedPieces)
                      : ""));
  if (!mesh->rankChunks.empty()) reportRanks(global, *mesh);
  detail(global, fmt::format("peak memory {}", formatBytes(peakRssBytes())));
  return Status{};
}

}  // namespace

void addReconstruct(CLI::App& app, const Global& global, Run& run) {
  auto options = std::make_shared<ReconstructCommand>();
  // A mesh for use, not for tiling (tiles simplify anyway): thinned unless asked not to.
  options->surface.reconstruct.decimateVoxels = kReconstructDecimateVoxels;
  CLI::App* sub = app.add_subcommand(
      "reconstruct", "A surface (triangle mesh) from a point cloud, chunk by chunk");
  sub->add_option("CLOUD", options->input, "A .las .laz .ply .xyz .txt .csv or .pts point cloud")
      ->required();
  sub->add_option("-o,--output", options->output, "The .ply mesh to write")->required();
  addSurfaceOptions(*sub, options->surface);
  sub->add_option("--chunk-size", options->surface.reconstruct.chunkVoxels,
                  "Voxels along a chunk's edge (default 64)")
      ->check(CLI::Range(2, 1024));
  sub->add_flag("--salvage", options->salvage,
                "Read a PLY cut short up to its last whole point (with a warning)");
  sub->add_flag("--resume", options->resume,
                "Go on from an interrupted run with the same input and options: the runs of "
                "chunks it finished are kept in OUTPUT.work");
  sub->callback([&global, &run, options] {
    run = [&global, options]() -> Status { return runReconstruct(global, *options); };
  });
}

}  // namespace lodforge::cli
