// `lodforge tiles INPUT -o DIR`: a mesh of any size as a 3D Tiles 1.1 tileset (large-meshes
// paper §3.2–3.4): chunk grid, octree of simplified super-chunks, one GLB per tile.
#include <filesystem>

#include <fmt/format.h>

#include "cli.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/units.h"
#include "lodforge/tiles/tileset.h"

namespace lodforge::cli {

void addTiles(CLI::App& app, const Global& global, Run& run) {
  struct Options {
    std::string input, output;
    double chunkSize = 0;
    int levels = 0;
    double reduction = 0.2;
    double maxNormalDeviation = 30;
    std::string memory = "moderate";
    bool resume = false;
    std::string origin, crs;
    std::string compress = "none";
    bool noQuantization = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub =
      app.add_subcommand("tiles", "Write a 3D Tiles 1.1 tileset of a mesh or an assembly");
  sub->add_option("INPUT", options->input,
                  "A .ply .obj .stl .gltf or .glb mesh or assembly, or an .lfp package")
      ->required();
  sub->add_option("-o,--output", options->output, "The tileset directory to write")->required();
  sub->add_option("--chunk-size", options->chunkSize,
                  "Edge of a leaf chunk in model units (default: about 64K triangles per leaf)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--levels", options->levels, "Levels above the leaves (default: up to one root)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--reduction", options->reduction,
                  "Share of its children's triangles a parent tile keeps (default 0.2)")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--max-normal-deviation", options->maxNormalDeviation,
                  "Largest angle in degrees a simplification step may turn a face (default 30)")
      ->check(CLI::Range(0.0, 90.0));
  sub->add_option("--memory", options->memory,
                  "minimal (one thread), moderate (--threads, default a quarter of the cores) or "
                  "unbounded (every core, chunks kept in memory); --memory-limit caps the whole "
                  "build")
      ->check(CLI::IsMember({"minimal", "moderate", "unbounded"}));
  sub->add_option("--origin", options->origin,
                  "Place the model's (0,0,0) at LON,LAT,HEIGHT (degrees, metres) with x east, y "
                  "north, z up");
  sub->add_option("--crs", options->crs,
                  "The input's coordinate system (e.g. EPSG:32633), placed on Earth through PROJ");
  sub->add_option("--compress", options->compress,
                  "none, or meshopt: EXT_meshopt_compression (smaller tiles; CesiumJS and "
                  "three.js decode it)")
      ->check(CLI::IsMember({"none", "meshopt"}));
  sub->add_flag("--no-quantization", options->noQuantization,
                "Float positions and normals everywhere instead of KHR_mesh_quantization (16-bit "
                "positions, 8-bit normals) in the tiles where it is invisible");
  sub->add_flag("--resume", options->resume,
                "Continue an interrupted run from OUTPUT.work and OUTPUT.partial (same input and "
                "options)");
  sub->callback([&global, &run, options] {
    run = [&global, options]() -> Status {
      TilesOptions tiles;
      tiles.input.chunkSize = options->chunkSize;
      tiles.octree.levels = options->levels;
      tiles.octree.keep = options->reduction;
      tiles.octree.maxNormalDeviationDegrees = options->maxNormalDeviation;
      tiles.memory = options->memory == "minimal"     ? TilesMemory::kMinimal
                     : options->memory == "unbounded" ? TilesMemory::kUnbounded
                                                      : TilesMemory::kModerate;
      tiles.threads = static_cast<int>(global.threads);
      tiles.memoryLimit = global.memoryLimit;
      tiles.resume = options->resume;
      tiles.crs = options->crs;
      tiles.meshoptCompression = options->compress == "meshopt";
      tiles.quantize = !options->noQuantization;
      if (!options->origin.empty()) {
        if (!options->crs.empty())
          return Error{ErrorKind::kUsage,
                       "--origin and --crs: give one (a CRS already places the model)"};
        Result<Geodetic> origin = parseOrigin(options->origin);
        if (!origin) return origin.status();
        tiles.origin = *origin;
      }
      Result<TilesStats> stats = writeTiles(options->input, options->output, tiles);
      if (!stats) {
        if (std::filesystem::exists(options->output + ".work/state.json"))
          fmt::print(
              stderr,
              "lodforge: the finished chunks and tiles are kept in {0}.work and {0}.partial: "
              "run again with --resume to continue, or delete them\n",
              options->output);
        return stats.status();
      }
      say(global,
          fmt::format(
              "wrote {}: {} tiles ({} leaves, {} levels above them), {} in {:.1f} s ({} "
              "input triangles/s)",
              options->output, formatCount(stats->tiles), formatCount(stats->leaves), stats->levels,
              formatBytes(stats->outputBytes), stats->seconds,
              formatCount(static_cast<std::uint64_t>(static_cast<double>(stats->inputTriangles) /
                                                     std::max(stats->seconds, 1e-9)))));
      detail(global,
             fmt::format("{} ({:.1f} s to chunks); {} threads; chunk size {:.4g}; {} triangles "
                         "after cutting; parents "
                         "kept {} border vertices of {} ({:.1f} %, at most {} in one tile) and "
                         "left out {} small segments; peak memory {}",
                         stats->resumed    ? "chunks resumed"
                         : stats->streamed ? "streamed"
                                           : "loaded whole",
                         stats->chunkSeconds, stats->threads, stats->chunkSize,
                         formatCount(stats->leafTriangles), formatCount(stats->lockedVertices),
                         formatCount(stats->vertices),
                         100.0 * static_cast<double>(stats->lockedVertices) /
                             static_cast<double>(std::max<std::uint64_t>(1, stats->vertices)),
                         formatCount(stats->maxLockedVertices), formatCount(stats->droppedSegments),
                         formatBytes(peakRssBytes())));
      return {};
    };
  });
}

}  // namespace lodforge::cli
