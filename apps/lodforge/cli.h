// What every subcommand shares: global options, size arguments with K/M/G suffixes, and how a
// subcommand reports its outcome (a Status that main turns into an exit code).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "lodforge/core/status.h"

namespace lodforge::cli {

struct Global {
  unsigned threads = 0;           // 0: all cores; more than the cores is lowered to them
  int verbosity = 0;              // -1 quiet, 0 normal, 1 verbose
  std::uint64_t memoryLimit = 0;  // bytes, 0: unlimited
};

// A subcommand's body; main runs the one the user chose.
using Run = std::function<Status()>;

// An option taking a count with decimal suffixes (10K = 10,000; 100M; 1G).
CLI::Option* addCountOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                            const std::string& description);
// An option taking a byte size with binary suffixes (512M = 512 MiB, 2G).
CLI::Option* addByteSizeOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                               const std::string& description);

// --threads N: 0 (all cores) or a count; anything else is a usage error that says so.
CLI::Option* addThreadsOption(CLI::App& app, unsigned& target);
// Lowers --threads above the machine's cores to them, with a note.
Status checkThreads(Global& global);
// Under mpirun or srun with several ranks: a subcommand that does not run across them is a
// usage error (each rank would do the whole work again).
Status checkClusterCommand(const CLI::App& app);
// --memory-limit: refused when 0 (it would mean nothing) and for a subcommand that does not
// honour it, before any work.
Status checkMemoryLimit(const CLI::App& app, const CLI::Option& option, std::uint64_t limit);
// A mesh-only subcommand given a point file (by its extension): a usage error that says what to
// run instead.
Status refusePointCloud(const std::string& input, std::string_view command);
// Runs a subcommand; an exception that still escapes becomes an error (exit 1), never an abort.
Status runGuarded(const Run& run);

// A steady-clock duration in milliseconds, for the timings the commands print.
double milliseconds(std::chrono::steady_clock::duration d);

// Normal output (suppressed by -q) and verbose output (shown with -v).
void say(const Global& global, const std::string& text);
void detail(const Global& global, const std::string& text);

void addInfo(CLI::App& app, const Global& global, Run& run);
void addBuild(CLI::App& app, const Global& global, Run& run);
void addExtract(CLI::App& app, const Global& global, Run& run);
void addConvert(CLI::App& app, const Global& global, Run& run);
void addGenerate(CLI::App& app, const Global& global, Run& run);
void addBench(CLI::App& app, const Global& global, Run& run);
void addCompare(CLI::App& app, const Global& global, Run& run);
void addRender(CLI::App& app, const Global& global, Run& run);
void addView(CLI::App& app, const Global& global, Run& run);
void addTiles(CLI::App& app, const Global& global, Run& run);
void addPoints(CLI::App& app, const Global& global, Run& run);
void addReconstruct(CLI::App& app, const Global& global, Run& run);
void addServe(CLI::App& app, const Global& global, Run& run);

}  // namespace lodforge::cli
