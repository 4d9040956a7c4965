// The point-package runtime behind `lodforge view` and `lodforge bench` for .lfc files.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cli.h"
#include "view_options.h"

namespace lodforge::cli {

// The camera path and viewport (PathChoice) as bench and view of a package take them.
struct CloudRunOptions : PathChoice {
  std::string input;
  bool play = false;                       // view: play the path instead of the mouse
  std::vector<double> foveaRadii = {200};  // bench: one run per radius; view: the first
  double fovealSplat = 2;
  std::size_t residentBlocks = 8;  // the paper's experiments keep 8
  std::size_t loadsPerFrame = 2;
  bool render = false;  // bench: draw every frame headless
  std::string json;     // bench: per-frame figures
  std::uint64_t stopAfter = 0;
  std::string screenshot;
};

// --fovea, --foveal-splat, --resident-blocks and --loads-per-frame, for view and bench.
void addCloudOptions(CLI::App& sub, CloudRunOptions& options, bool severalRadii);

// Bench and view are given a point package: its run takes their input, path and viewport (and
// a fovea of 200 pixels unless --fovea gave one).
void takePackageRun(CloudRunOptions& cloud, const std::string& input, const PathChoice& choice);

Status runCloudBench(const Global& global, const CloudRunOptions& options);
Status runCloudView(const Global& global, const CloudRunOptions& options);

}  // namespace lodforge::cli
