// Where the octree keeps node meshes while it builds (large-meshes paper §3.4): work files, with
// a summary beside each finished node's for --resume, or memory in the unbounded mode. A mesh is
// saved once its node is built and taken once by its parent.
#pragma once

#include <map>
#include <mutex>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/tiling/mesh_part.h"
#include "lodforge/tiling/octree.h"

namespace lodforge {

class NodeStore {
 public:
  explicit NodeStore(const OctreeOptions& options) : options_(options) {}

  // The node's mesh file in the work directory (a key when kept in memory).
  std::string meshPath(const OctreeNode& node) const;
  // Takes the mesh: kept in memory it moves into the map, on disk it is written.
  Status save(MeshPart&& mesh, const std::string& path);
  Result<MeshPart> take(const std::string& path);
  // Written last for a finished node, so that its presence means done (nothing in memory).
  Status writeSummary(const OctreeNode& node) const;
  // With --resume: a node is done when its summary is there and its mesh too, unless its
  // parent is done as well (which removed the mesh: nothing needs it any more). Fills the node.
  bool resumeNode(OctreeNode& node, const OctreeNode* parent) const;
  // A work file nothing needs any more, even to resume (nothing in memory).
  void release(const std::string& path) const;

 private:
  const OctreeOptions& options_;
  std::mutex mutex_;
  std::map<std::string, MeshPart> inMemory_;  // keepInMemory: node meshes by path
};

}  // namespace lodforge
