#include "cli.h"

#include <algorithm>
#include <exception>

#include <fmt/format.h>

#include "lodforge/core/cluster.h"
#include "lodforge/core/threads.h"
#include "lodforge/core/units.h"
#include "lodforge/io/points/point_reader.h"

namespace lodforge::cli {

namespace {
// An option whose text goes through `parse`; CLI11 reports a failure as a usage error (exit 2).
CLI::Option* addParsedOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                             const std::string& description,
                             std::optional<std::uint64_t> (*parse)(std::string_view),
                             const char* expected, const char* typeName) {
  return app
      .add_option_function<std::string>(
          name,
          [&target, name, parse, expected](const std::string& text) {
            const auto value = parse(text);
            if (!value) throw CLI::ValidationError(name, expected);
            target = *value;
          },
          description)
      ->type_name(typeName);
}
}  // namespace

CLI::Option* addCountOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                            const std::string& description) {
  return addParsedOption(app, name, target, description, parseCount,
                         "expected a count such as 5000, 10K, 100M or 1G", "N");
}

CLI::Option* addByteSizeOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                               const std::string& description) {
  return addParsedOption(app, name, target, description, parseByteSize,
                         "expected a size such as 512M or 2G", "SIZE");
}

CLI::Option* addThreadsOption(CLI::App& app, unsigned& target) {
  return app
      .add_option_function<std::string>(
          "--threads",
          [&target](const std::string& text) {
            const auto value = parseCount(text);
            if (!value || *value > 65536)
              throw CLI::ValidationError("--threads",
                                         "expected 0 (all cores) or a number of threads such as 4");
            target = static_cast<unsigned>(*value);
          },
          "Threads to use: 0 or left out for all cores")
      ->type_name("N");
}

Status checkThreads(Global& global) {
  const unsigned cores = hardwareThreads();
  if (global.threads <= cores) return {};
  if (global.verbosity >= 0)
    fmt::print(stderr,
               "lodforge: note: --threads {}: this process may run on {} cores (its CPU "
               "affinity); using {}\n",
               global.threads, cores, cores);
  global.threads = cores;
  return {};
}

Status checkClusterCommand(const CLI::App& app) {
  if (!clustered()) return {};
  for (const CLI::App* command : app.get_subcommands())
    if (command->get_name() != "tiles" && command->get_name() != "reconstruct")
      return Error{ErrorKind::kUsage,
                   fmt::format("`{}` runs as one process; only `tiles` and `reconstruct` run "
                               "across the ranks of an mpirun or srun job (docs/distributed.md)",
                               command->get_name())};
  return {};
}

Status checkMemoryLimit(const CLI::App& app, const CLI::Option& option, std::uint64_t limit) {
  if (option.count() == 0) return {};
  if (limit == 0)
    return Error{ErrorKind::kUsage,
                 "--memory-limit 0 means nothing: give a size such as 512M, or leave it out for no "
                 "limit"};
  static constexpr std::string_view kHonoured[] = {"tiles", "points", "build", "convert",
                                                   "reconstruct"};
  for (const CLI::App* sub : app.get_subcommands()) {
    const std::string& name = sub->get_name();
    if (std::find(std::begin(kHonoured), std::end(kHonoured), name) == std::end(kHonoured))
      return Error{ErrorKind::kUsage,
                   fmt::format("{} does not take --memory-limit (tiles, points, build, "
                               "convert and reconstruct do)",
                               name)};
  }
  return {};
}

Status refusePointCloud(const std::string& input, std::string_view command) {
  if (!isPointCloudPath(input)) return {};
  return Error{ErrorKind::kUsage,
               fmt::format("{}: a point cloud; {} takes meshes (for points use `lodforge points` "
                           "for a point package or `lodforge tiles` for 3D Tiles)",
                           input, command)};
}

Status runGuarded(const Run& run) {
  try {
    return run();
  } catch (const std::exception& e) {
    return Error{ErrorKind::kInternal, fmt::format("unexpected failure: {}", e.what())};
  } catch (...) {
    return Error{ErrorKind::kInternal, "unexpected failure"};
  }
}

double milliseconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

void say(const Global& global, const std::string& text) {
  if (global.verbosity >= 0) fmt::print("{}\n", text);
}

void detail(const Global& global, const std::string& text) {
  if (global.verbosity > 0) fmt::print(stderr, "{}\n", text);
}

}  // namespace lodforge::cli
