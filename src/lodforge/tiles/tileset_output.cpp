#include "lodforge/tiles/tileset_output.h"

#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/tiles/tileset_parts.h"

namespace lodforge {

bool isLodforgeTileset(const std::string& directory) {
  Result<std::string> text = readFileToString(directory + "/tileset.json", std::uint64_t{1} << 28);
  if (!text) return false;
  const nlohmann::json tileset = nlohmann::json::parse(*text, nullptr, false);
  if (tileset.is_discarded() || !tileset.is_object()) return false;
  const auto asset = tileset.find("asset");
  if (asset == tileset.end() || !asset->is_object()) return false;
  const auto generator = asset->find("generator");
  if (generator == asset->end() || !generator->is_string() ||
      !generator->get<std::string>().starts_with("lodforge"))
    return false;
  return directoryHoldsOnly(directory, [](const std::string& relative, bool isDirectory) {
    if (relative == "tileset.json" || relative == kPartsFileName) return !isDirectory;
    if (relative == "tiles") return isDirectory;
    return relative.starts_with("tiles/") && relative.ends_with(".glb") && !isDirectory &&
           relative.find('/', 6) == std::string::npos;
  });
}

OutputKind tilesetOutput() {
  return {.name = "a tileset", .directory = true, .isOwn = isLodforgeTileset};
}

Status claimTilesetOutput(const std::string& input, const std::string& outputDirectory) {
  const std::string inputs[] = {input};
  return claimOutput(outputDirectory, tilesetOutput(), inputs);
}

}  // namespace lodforge
