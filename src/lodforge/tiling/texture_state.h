// A textured input's tables in the chunk state of a resumable `tiles` run (resume.h): materials
// and images as JSON, an embedded image's bytes as a file in the work directory, and each image
// file's size and modification time, so a resumed run takes the table only while its images are
// the ones it started from.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "lodforge/core/material.h"
#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_input.h"

namespace lodforge {

// Every field of each material, its texture and wrap modes included. Reading throws
// nlohmann::json::exception when malformed and gives nothing for an unknown mode.
nlohmann::json materialsToJson(const std::vector<Material>& materials);
std::optional<std::vector<Material>> materialsFromJson(const nlohmann::json& list);

// The table as JSON, writing embedded images into `workDirectory`/images.
Result<nlohmann::json> saveTextureTable(const TextureTable& table,
                                        const std::string& workDirectory);
// The table back; nothing when an image file changed or went, an embedded image's file is
// damaged, or a material names an image the table lacks. Throws nlohmann::json::exception when
// malformed (resumeChunks catches it: chunk again).
std::optional<TextureTable> loadTextureTable(const nlohmann::json& state,
                                             const std::string& workDirectory);

}  // namespace lodforge
