// STEP out through the OpenCASCADE module: an assembly of prisms and sheets (cad_module.h's
// WriteRequest) written under a temporary name and renamed when complete.
#pragma once

#include "lodforge/core/status.h"
#include "lodforge/io/cad/cad_module.h"

namespace lodforge {

// Writes request.path (the request's own path is replaced by a temporary beside it).
Status writeStepAssembly(cad::WriteRequest request);

}  // namespace lodforge
