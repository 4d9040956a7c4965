#include "lodforge/tiles/tileset_json.h"

#include <algorithm>
#include <functional>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "lodforge/core/file.h"
#include "lodforge/tiles/tile_content.h"

namespace lodforge {

namespace {

nlohmann::json boxOf(const Aabbd& bounds) {
  return {{"box", tileBox(bounds)}};
}

}  // namespace

std::array<double, 12> tileBox(const Aabbd& bounds) {
  const Vec3d c = bounds.center(), h = bounds.size() * 0.5;
  return {c.x, c.y, c.z, h.x, 0, 0, 0, h.y, 0, 0, 0, h.z};
}

std::string tileContentUri(const OctreeNode& node) {
  return fmt::format("tiles/{}-{}-{}-{}.glb", node.level, node.cell[0], node.cell[1], node.cell[2]);
}

std::vector<double> declaredTileErrors(const OctreeResult& octree, bool quantized) {
  // Children come before their parents in the node list: one pass collects each subtree's
  // largest quantisation error.
  std::vector<double> quantization(octree.nodes.size(), 0.0);
  std::vector<double> errors(octree.nodes.size());
  for (std::size_t i = 0; i < octree.nodes.size(); ++i) {
    const OctreeNode& node = octree.nodes[i];
    quantization[i] = tileQuantizationError(node, quantized && tileQuantized(node));
    for (std::uint32_t c : node.children)
      quantization[i] = std::max(quantization[i], quantization[c]);
    errors[i] = node.geometricError + quantization[i];
  }
  return errors;
}

double nothingShownError(const OctreeResult& octree, double rootError) {
  return std::max(rootError * 2, length(octree.nodes[octree.root].bounds.size()));
}

Status writeTilesetJson(const OctreeResult& octree, const std::string& path,
                        const std::optional<Mat4d>& rootTransform, bool quantized,
                        const std::string& partsUri) {
  const std::vector<double> errors = declaredTileErrors(octree, quantized);
  // Depth first; children listed in node order.
  std::function<nlohmann::json(std::uint32_t)> tile = [&](std::uint32_t index) {
    const OctreeNode& node = octree.nodes[index];
    nlohmann::json out = {{"boundingVolume", boxOf(node.bounds)},
                          {"geometricError", errors[index]},
                          {"refine", "REPLACE"}};
    if (hasTileContent(node)) out["content"] = {{"uri", tileContentUri(node)}};
    if (!node.children.empty()) {
      out["children"] = nlohmann::json::array();
      for (std::uint32_t c : node.children) out["children"].push_back(tile(c));
    }
    return out;
  };
  // Above the root: the error of showing nothing at all, the size of the model.
  nlohmann::json tileset = {
      {"asset", {{"version", "1.1"}, {"generator", "lodforge " LODFORGE_VERSION}}},
      {"geometricError", nothingShownError(octree, errors[octree.root])},
      {"root", tile(octree.root)}};
  if (rootTransform) tileset["root"]["transform"] = rootTransform->m;
  if (!partsUri.empty()) tileset["asset"]["extras"]["parts"] = partsUri;
  // Compact: half the bytes of an indented listing (a viewer reads it whole before its first
  // frame).
  return OutputFile::writeWhole(path, tileset.dump() + '\n');
}

}  // namespace lodforge
