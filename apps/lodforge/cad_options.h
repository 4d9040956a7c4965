// The tessellation options of every command that reads CAD files (STEP, IGES, BREP):
// --deflection, --angle, --code-page and --hidden (docs/cad.md).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "cli.h"
#include "lodforge/core/status.h"
#include "lodforge/io/cad/cad_reader.h"

namespace lodforge::cli {

struct CadCommand {
  std::string deflection = "0.001";
  double angle = CadReadOptions{}.angleDegrees;
  std::string codePage;
  bool hidden = false;
};

void addCadOptions(CLI::App& sub, CadCommand& options);

// "0.002" is relative to each part's size; "0.1mm", "2cm" or "0.05m" is a length.
Result<CadReadOptions> cadOptions(const CadCommand& options, const Global& global);

}  // namespace lodforge::cli
