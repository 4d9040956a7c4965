#include "lodforge/tiles/tileset_output.h"

#include <filesystem>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/tiles/tileset_parts.h"

namespace lodforge {

namespace {

// An implicit tileset's folders FOLDER/L, FOLDER/L/X, FOLDER/L/X/Y and files FOLDER/L/X/Y/Z.EXT
// (implicit_tiling.h), every name a number.
bool implicitEntry(std::string_view relative, std::string_view folder, std::string_view extension,
                   bool isDirectory) {
  if (!relative.starts_with(folder) || relative.size() <= folder.size() + 1 ||
      relative[folder.size()] != '/')
    return false;
  std::string_view rest = relative.substr(folder.size() + 1);
  if (!isDirectory) {
    if (!rest.ends_with(extension)) return false;
    rest.remove_suffix(extension.size());
  }
  int names = 0;
  while (true) {
    const std::size_t slash = rest.find('/');
    const std::string_view name = rest.substr(0, slash);
    if (name.empty() || name.find_first_not_of("0123456789") != std::string_view::npos)
      return false;
    ++names;
    if (slash == std::string_view::npos) break;
    rest.remove_prefix(slash + 1);
  }
  return isDirectory ? names <= 3 : names == 4;
}

}  // namespace

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
    if (relative == "tiles" || relative == "subtrees") return isDirectory;
    if (implicitEntry(relative, "tiles", ".glb", isDirectory) ||
        implicitEntry(relative, "subtrees", ".subtree", isDirectory))
      return true;
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

namespace {

// Whether `name` is a temporary an OutputFile makes ("<name>.tmp-<pid>-<n>").
bool outputTemporary(std::string_view name) {
  const std::size_t at = name.rfind(".tmp-");
  return at != std::string_view::npos && leftoverProcess(name, name.substr(0, at)).has_value();
}

}  // namespace

void removeOutputTemporaries(const std::string& stagingDirectory) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::exists(stagingDirectory, error)) return;
  std::vector<fs::path> temporaries;
  for (const auto& entry : fs::recursive_directory_iterator(stagingDirectory, error))
    if (entry.is_regular_file(error) && outputTemporary(entry.path().filename().string()))
      temporaries.push_back(entry.path());
  for (const fs::path& path : temporaries) fs::remove(path, error);
}

}  // namespace lodforge
