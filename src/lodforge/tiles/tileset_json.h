// tileset.json of a mesh tileset (3D Tiles 1.1): the octree's nodes as tiles with box volumes,
// measured geometric errors and REPLACE refinement.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

// tileset.json for a built octree: asset 1.1, REPLACE refinement, box volumes, geometric errors,
// contents at tiles/<name>.glb for the nodes with triangles, and the root's transform (local
// frame to ECEF) when georeferenced. With `quantized` contents, each geometric error also holds
// the largest quantisation error in the tile's subtree (still non-increasing parent to child).
// `partsUri`, when given, goes to asset.extras.parts (tileset_parts.h).
Status writeTilesetJson(const OctreeResult& octree, const std::string& path,
                        const std::optional<Mat4d>& rootTransform = std::nullopt,
                        bool quantized = false, const std::string& partsUri = {});

// Each node's declared geometric error: its own plus, with `quantized` contents, the largest
// quantisation error in its subtree (still non-increasing parent to child).
std::vector<double> declaredTileErrors(const OctreeResult& octree, bool quantized);

// The tileset's own geometricError (showing nothing at all): the size of the model, or twice the
// root's declared error if larger.
double nothingShownError(const OctreeResult& octree, double rootError);

// A tile's "box" bounding volume for axis-aligned bounds: centre, then three half-axes.
std::array<double, 12> tileBox(const Aabbd& bounds);

// Whether a node has a content file (triangles, written by the builder).
inline bool hasTileContent(const OctreeNode& node) {
  return node.triangles > 0 && !node.meshPath.empty();
}

// The relative URI of a node's content.
std::string tileContentUri(const OctreeNode& node);

}  // namespace lodforge
