#include "lodforge/tiling/node_store.h"

#include <filesystem>

#include <fmt/format.h>

#include "lodforge/tiling/mesh_file.h"
#include "lodforge/tiling/resume.h"

namespace lodforge {

std::string NodeStore::meshPath(const OctreeNode& node) const {
  return fmt::format("{}/L{}_{}_{}_{}.mesh", options_.workDirectory, node.level, node.cell[0],
                     node.cell[1], node.cell[2]);
}

Status NodeStore::save(MeshPart&& mesh, const std::string& path) {
  if (!options_.keepInMemory) return saveMesh(mesh, path);
  std::lock_guard lock(mutex_);
  inMemory_[path] = std::move(mesh);
  return {};
}

Result<MeshPart> NodeStore::take(const std::string& path) {
  if (!options_.keepInMemory) return loadMesh(path);  // kept for a resumed run
  std::lock_guard lock(mutex_);
  auto node = inMemory_.extract(path);
  if (node.empty()) return Error{ErrorKind::kInternal, path + ": node mesh missing"};
  return std::move(node.mapped());
}

Status NodeStore::writeSummary(const OctreeNode& node) const {
  if (options_.keepInMemory) return {};
  return writeNodeSummary(node);
}

bool NodeStore::resumeNode(OctreeNode& node, const OctreeNode* parent) const {
  if (!options_.resume || options_.keepInMemory) return false;
  const std::string mesh = meshPath(node);
  std::error_code ignored;
  const bool parentDone =
      parent != nullptr && std::filesystem::exists(nodeSummaryPath(meshPath(*parent)), ignored);
  if (!parentDone && !std::filesystem::exists(mesh, ignored)) return false;
  if (!readNodeSummary(nodeSummaryPath(mesh), node)) return false;
  node.meshPath = mesh;
  return true;
}

void NodeStore::release(const std::string& path) const {
  if (options_.keepInMemory) return;
  std::error_code ignored;  // what is left goes with the work directory
  std::filesystem::remove(path, ignored);
}

}  // namespace lodforge
