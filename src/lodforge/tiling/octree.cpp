#include "lodforge/tiling/octree.h"

#include <algorithm>
#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "lodforge/tiling/mesh_part.h"
#include "lodforge/tiling/node_scheduler.h"
#include "lodforge/tiling/node_store.h"
#include "lodforge/tiling/octree_share.h"
#include "lodforge/tiling/simplify_node.h"

namespace lodforge {
namespace {

// The tree before anything is built, and what the build needs to walk it.
struct OctreePlan {
  OctreeResult result;
  std::vector<std::uint64_t> inputTriangles;  // per node: what it is built from
  std::vector<std::uint32_t> parentOf;        // per node (kNoParent for the top level)
  std::vector<std::uint32_t> topLevel;
};

// The whole tree from the leaf cells alone: leaves first, then level by level, 2x2x2 nodes of a
// level under one parent, up to one root or --levels.
OctreePlan planOctree(const ChunkWriter& chunks, int levels) {
  OctreePlan plan;
  OctreeResult& result = plan.result;
  std::vector<std::uint64_t>& inputTriangles = plan.inputTriangles;
  std::vector<std::uint32_t> level;
  for (const auto& [index, count] : chunks.triangleCounts()) {
    OctreeNode node;
    node.cell = cellOfIndex(chunks.grid(), index);
    level.push_back(static_cast<std::uint32_t>(result.nodes.size()));
    result.nodes.push_back(std::move(node));
    inputTriangles.push_back(count);
  }
  int depth = 0;
  while (level.size() > 1 && (levels == 0 || depth < levels)) {
    ++depth;
    // 2x2x2 nodes of this level share a parent.
    std::map<ChunkCell, std::vector<std::uint32_t>> groups;
    for (std::uint32_t i : level) {
      const ChunkCell& c = result.nodes[i].cell;
      groups[{c[0] >> 1, c[1] >> 1, c[2] >> 1}].push_back(i);
    }
    std::vector<std::uint32_t> parents;
    for (auto& [cell, children] : groups) {
      OctreeNode node;
      node.level = depth;
      node.cell = cell;
      node.children = std::move(children);
      parents.push_back(static_cast<std::uint32_t>(result.nodes.size()));
      result.nodes.push_back(std::move(node));
      inputTriangles.push_back(0);  // known once its children are built
    }
    level = std::move(parents);
  }
  result.levels = depth;
  plan.topLevel = std::move(level);
  std::vector<std::uint32_t>& parentOf = plan.parentOf;
  parentOf.assign(result.nodes.size(), kNoParent);
  for (std::uint32_t i = 0; i < result.nodes.size(); ++i)
    for (std::uint32_t c : result.nodes[i].children) parentOf[c] = i;
  return plan;
}

// Stopped below a single root (--levels): a root without content over the top level.
void finishRoot(OctreePlan& plan) {
  OctreeResult& result = plan.result;
  const std::vector<std::uint32_t>& topLevel = plan.topLevel;
  if (topLevel.size() == 1) {
    result.root = topLevel[0];
    return;
  }
  OctreeNode root;
  root.level = result.levels + 1;
  root.children = topLevel;
  for (std::uint32_t c : topLevel) {
    root.bounds.add(result.nodes[c].bounds);
    root.geometricError = std::max(root.geometricError, result.nodes[c].geometricError);
  }
  root.geometricError = std::max(root.geometricError * 2, root.bounds.longestSide() / 100);
  result.root = static_cast<std::uint32_t>(result.nodes.size());
  result.nodes.push_back(std::move(root));
}

// Builds the planned nodes: leaves from their chunks, parents from their children (§3.3), each
// handed to the sink and saved in the store as soon as it is built.
class OctreeBuild {
 public:
  OctreeBuild(const ChunkWriter& chunks, const OctreeOptions& options, const NodeSink& sink,
              OctreePlan& plan)
      : chunks_(chunks), options_(options), sink_(sink), plan_(plan), store_(options) {}

  Status run() {
    if (options_.ranks > 1) {
      share_ = shareOctree(plan_.result.nodes, plan_.inputTriangles, options_.ranks);
      plan_.result.splitLevel = share_.splitLevel;
      plan_.result.rankWork = share_.work;
    }
    return buildWhenReady(plan_.result.nodes, plan_.parentOf, plan_.inputTriangles,
                          {.threads = options_.threads,
                           .memoryBudget = options_.memoryBudget,
                           .textured = chunks_.textured(),
                           .quiet = options_.quiet},
                          [this](std::uint32_t index) -> Status {
                            if (!share_.owner.empty() && !mine(index))
                              return needed(index) ? takeDone(index) : Status{};
                            OctreeNode& node = plan_.result.nodes[index];
                            return node.level == 0 ? buildLeaf(index) : buildParent(index);
                          });
  }

 private:
  // In a job of several ranks: a node this rank builds in this round; one of an earlier round
  // that a node it builds needs (a child, built by some rank).
  bool mine(std::uint32_t index) const {
    return share_.round[index] == options_.round && share_.owner[index] == options_.rank;
  }
  bool needed(std::uint32_t index) const {
    const std::uint32_t up = plan_.parentOf[index];
    return share_.round[index] < options_.round && up != kNoParent && mine(up);
  }
  Status takeDone(std::uint32_t index) {
    if (resumed(index)) return {};
    return Error{ErrorKind::kIo, fmt::format("{}: the node is not done, though its round is "
                                             "over (is the work directory on a file system "
                                             "every rank shares?)",
                                             store_.meshPath(plan_.result.nodes[index]))};
  }

  // With --resume, a node a previous run finished is taken as it is.
  bool resumed(std::uint32_t index) {
    const std::uint32_t up = plan_.parentOf[index];
    return store_.resumeNode(plan_.result.nodes[index],
                             up == kNoParent ? nullptr : &plan_.result.nodes[up]);
  }

  // The node's mesh to the sink, then to the store, then its summary (which marks it done).
  Status finish(OctreeNode& node, MeshPart&& mesh) {
    node.triangles = mesh.triangleCount();
    node.vertices = mesh.vertexCount();
    node.features = distinctFeatures(mesh);
    node.meshPath = store_.meshPath(node);
    LODFORGE_TRY(sink_(node, mesh));
    LODFORGE_TRY(store_.save(std::move(mesh), node.meshPath));
    return store_.writeSummary(node);
  }

  Status buildLeaf(std::uint32_t index) {
    if (resumed(index)) return {};
    OctreeNode& node = plan_.result.nodes[index];
    Result<MeshPart> mesh = chunks_.load(node.cell);
    if (!mesh) return mesh.status();
    node.bounds = boundsOf(*mesh);
    LODFORGE_TRY(finish(node, std::move(*mesh)));
    // The chunk is no longer needed, even to resume: its work file goes now, while its pages
    // may still be unwritten, rather than in one long removal at the end.
    for (const std::string& file : chunks_.chunkFiles(node.cell)) store_.release(file);
    return {};
  }

  Status buildParent(std::uint32_t index) {
    if (resumed(index)) return {};
    OctreeNode& node = plan_.result.nodes[index];
    std::vector<MeshPart> parts;
    double childError = 0;
    for (std::uint32_t c : node.children) {
      const OctreeNode& child = plan_.result.nodes[c];
      Result<MeshPart> part = store_.take(child.meshPath);
      if (!part) return part.status();
      parts.push_back(std::move(*part));
      node.bounds.add(child.bounds);
      childError = std::max(childError, child.geometricError);
    }
    SimplifiedNode simplified = simplifyNode(std::move(parts), chunks_.grid(), node, options_);
    node.droppedSegments = simplified.droppedSegments;
    node.lockedVertices = simplified.lockedVertices;
    // Plus what the children already deviate from the finest: the triangle inequality keeps it
    // an upper bound and makes it non-increasing from parent to child.
    node.geometricError = childError + simplified.simplificationError + simplified.droppedError;
    LODFORGE_TRY(finish(node, std::move(simplified.mesh)));
    // The children's meshes are no longer needed, even to resume (their summaries stay).
    for (std::uint32_t c : node.children) store_.release(plan_.result.nodes[c].meshPath);
    return {};
  }

  const ChunkWriter& chunks_;
  const OctreeOptions& options_;
  const NodeSink& sink_;
  OctreePlan& plan_;
  NodeStore store_;
  OctreeShare share_;  // empty in a job of one
};

}  // namespace

ShareCounts countShare(const ChunkWriter& chunks, const OctreeOptions& options) {
  if (chunks.triangleCounts().empty()) return {};
  const OctreePlan plan = planOctree(chunks, options.levels);
  const OctreeShare share = shareOctree(plan.result.nodes, plan.inputTriangles, options.ranks);
  ShareCounts counts{share.rounds, plan.result.nodes.size(),
                     std::vector<std::uint64_t>(static_cast<std::size_t>(share.rounds), 0)};
  for (std::size_t i = 0; i < share.owner.size(); ++i)
    if (share.owner[i] == options.rank) ++counts.mine[static_cast<std::size_t>(share.round[i])];
  return counts;
}

Result<OctreeResult> buildOctree(const ChunkWriter& chunks, const OctreeOptions& options,
                                 const NodeSink& sink) {
  if (!options.keepInMemory) {
    std::error_code error;
    std::filesystem::create_directories(options.workDirectory, error);
    if (error)
      return ioError(options.workDirectory, fmt::format("cannot create: {}", error.message()));
  }
  if (chunks.triangleCounts().empty())
    return Error{ErrorKind::kBadInput, "the input has no triangles"};
  OctreePlan plan = planOctree(chunks, options.levels);
  OctreeBuild build(chunks, options, sink, plan);
  LODFORGE_TRY(build.run());
  finishRoot(plan);
  return std::move(plan.result);
}

}  // namespace lodforge
