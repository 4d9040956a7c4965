// Wavefront OBJ writer: one `o` per object, `v x y z [r g b]`, `vn`, triangles as `f`.
#pragma once

#include <string>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

Status writeObj(const Model& model, const std::string& path);

}  // namespace lodforge
