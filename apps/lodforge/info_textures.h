// What `lodforge info` says of a model's textures: its materials (which draw an image, and how
// it wraps), its images (file or embedded, format, size, channels) and the memory their texels
// take decoded, with mipmaps, as a viewer holds them.
#pragma once

#include <nlohmann/json.hpp>

#include "lodforge/core/model.h"

namespace lodforge::cli {

// {"materials": [{"name", "image", "wrap"}], "images": [{"name", "file" or "embeddedBytes",
// "format", "width", "height", "channels"}], "textureBytes"}; empty for a model without images.
nlohmann::json textureSummary(const Model& model);
// The lines `info` prints for that summary.
void printTextures(const nlohmann::json& textures);

}  // namespace lodforge::cli
