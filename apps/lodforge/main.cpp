// The `lodforge` command: one subcommand per file in this folder.
// Exit codes: 0 ok, 1 failure (I/O, limits, cancelled), 2 bad input or usage.
#include <cstdio>
#include <cstdlib>

#include <fmt/format.h>

#include "cli.h"
#include "lodforge/core/cluster.h"
#include "lodforge/core/memory.h"
#include "lodforge/core/progress.h"
#include "lodforge/core/threads.h"

namespace {

// Says a failure (in a job of several ranks: rank 0 what every rank knows, any rank what only
// it knows) and leaves the job; the exit code.
int finish(const lodforge::Status& status) {
  using namespace lodforge;
  const int code = exitCodeFor(status);
  if (!status.ok() && (clusterRank() == 0 || clusterAbandoned() || !clusterFailureAgreed()))
    fmt::print(stderr, "lodforge: {}{}\n",
               clustered() && clusterRank() != 0 && !clusterAbandoned()
                   ? fmt::format("rank {}: ", clusterRank())
                   : "",
               status.message());
  leaveCluster(code);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace lodforge;
  keepFreedMemoryForReuse();
  CLI::App app{"lodforge: level-of-detail data for massive 3D models", "lodforge"};
  app.set_version_flag("--version", "lodforge " LODFORGE_VERSION);
  app.require_subcommand(1);
  app.fallthrough();

  cli::Global global;
  cli::addThreadsOption(app, global.threads);
  app.add_flag_callback(
      "-v,--verbose", [&] { global.verbosity = 1; }, "More detail on stderr");
  app.add_flag_callback(
      "-q,--quiet", [&] { global.verbosity = -1; }, "Only errors (no progress, no summary)");
  CLI::Option* memoryLimit =
      cli::addByteSizeOption(app, "--memory-limit", global.memoryLimit,
                             "Memory the command may use (e.g. 2G); taken by tiles, points, build, "
                             "convert and reconstruct, which refuse a limit too small to work "
                             "with (exit 1, naming the least that works)");

  cli::Run run;
  cli::addInfo(app, global, run);
  cli::addConvert(app, global, run);
  cli::addBuild(app, global, run);
  cli::addExtract(app, global, run);
  cli::addTiles(app, global, run);
  cli::addPoints(app, global, run);
  cli::addReconstruct(app, global, run);
  cli::addServe(app, global, run);
  cli::addGenerate(app, global, run);
  cli::addBench(app, global, run);
  cli::addCompare(app, global, run);
  cli::addRender(app, global, run);
  cli::addView(app, global, run);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version end here too, with exit code 0.
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  // First, so that what follows is said once for a job of several ranks: rank 0 speaks for the
  // job (docs/distributed.md), and the checks, the same on every rank, are agreed.
  Status status = joinCluster();
  if (!status.ok()) return finish(status);
  if (const auto alone = tasksNotJoined(std::getenv("SLURM_STEP_NUM_TASKS")); alone)
    fmt::print(stderr, "lodforge: warning: {}\n", *alone);
  if (clusterRank() != 0) global.verbosity = -1;
  status = cli::checkMemoryLimit(app, *memoryLimit, global.memoryLimit);
  if (status.ok()) status = cli::checkThreads(global);
  if (status.ok()) status = cli::checkClusterCommand(app);
  status = agreeAcrossRanks(status);
  if (!status.ok()) return finish(status);
  if (global.verbosity < 0) setProgressMode(ProgressMode::kOff);
  installInterruptHandler();
  const ThreadLimit threads(global.threads);

  status = run ? cli::runGuarded(run) : Status(Error{ErrorKind::kUsage, "no subcommand"});
  return finish(status);
}
