// STL writer: binary (one solid, all objects) or ascii (one `solid` per object).
#pragma once

#include <string>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

struct StlWriteOptions {
  bool ascii = false;
};

Status writeStl(const Model& model, const std::string& path, const StlWriteOptions& options = {});

}  // namespace lodforge
