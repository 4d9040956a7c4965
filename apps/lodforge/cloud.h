// The point-package runtime behind `lodforge view` and `lodforge bench` for .lfc files.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cli.h"

namespace lodforge::cli {

struct CloudRunOptions {
  std::string input;
  std::string path = "orbit";  // orbit, fly or a camera path file
  bool play = false;           // view: play the path instead of the mouse
  std::uint64_t frames = 120;
  std::string size = "1280x720";
  double fovY = 60;
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

Status runCloudBench(const Global& global, const CloudRunOptions& options);
Status runCloudView(const Global& global, const CloudRunOptions& options);

}  // namespace lodforge::cli
