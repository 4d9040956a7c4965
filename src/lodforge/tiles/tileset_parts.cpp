#include "lodforge/tiles/tileset_parts.h"

#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/tiling/resume.h"

namespace lodforge {

std::vector<std::vector<std::uint32_t>> partsMissingPerLevel(const OctreeResult& octree,
                                                             std::size_t partCount) {
  std::vector<std::vector<std::uint8_t>> present(static_cast<std::size_t>(octree.levels) + 1,
                                                 std::vector<std::uint8_t>(partCount, 0));
  for (const OctreeNode& node : octree.nodes) {
    if (node.level < 0 || static_cast<std::size_t>(node.level) >= present.size()) continue;
    for (std::uint32_t f : node.features)
      if (f < partCount) present[static_cast<std::size_t>(node.level)][f] = 1;
  }
  std::vector<std::vector<std::uint32_t>> missing(present.size());
  for (std::size_t level = 0; level < present.size(); ++level) {
    for (std::uint32_t f = 0; f < partCount; ++f)
      if (present[level][f] == 0) missing[level].push_back(f);
  }
  return missing;
}

Status writePartsJson(const OctreeResult& octree, const PartTable& parts, const std::string& path) {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < parts.size(); ++i) {
    nlohmann::json part = {
        {"id", i},
        {"name", parts.names[i]},
        {"path", parts.paths[i]},
        {"bounds", parts.bounds[i].empty() ? nlohmann::json() : boundsToJson(parts.bounds[i])}};
    if (parts.layers[i] != kNoLayer)  // one per part, inside the table (resume checks both)
      part["layer"] = parts.layerTable[parts.layers[i]];
    list.push_back(std::move(part));
  }
  nlohmann::json levels = nlohmann::json::array();
  const auto missing = partsMissingPerLevel(octree, parts.size());
  for (std::size_t level = 0; level < missing.size(); ++level)
    levels.push_back({{"level", level}, {"missing", missing[level]}});
  const nlohmann::json document = {
      {"source", parts.source}, {"parts", std::move(list)}, {"levels", std::move(levels)}};
  // Names come from the input and may not be UTF-8: replaced rather than thrown on.
  return OutputFile::writeWhole(
      path, document.dump(1, ' ', false, nlohmann::json::error_handler_t::replace));
}

}  // namespace lodforge
