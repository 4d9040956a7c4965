// A model's texture images written beside a file format that names them rather than holds them
// (OBJ's material library, PLY's TextureFile comments): "<stem>_texture<i>.<ext>" next to the
// model, the image's own bytes. A file of that name is replaced only when it already holds the
// same bytes (a second run); anything else there is refused, never overwritten.
#pragma once

#include <string>
#include <vector>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

// The file names (relative to the model's folder) of the model's images, in its order, after
// writing them.
Result<std::vector<std::string>> writeImagesBeside(const Model& model, const std::string& path);

// Writes `text` to `path` (a side file: a material library) under the same rule.
Status writeSideFile(const std::string& path, std::string_view text);

}  // namespace lodforge
