// The octree of super-chunks (large-meshes paper §3.3): the chunks are the leaves; level by
// level, 2x2x2 nodes are combined into a parent whose mesh is their meshes welded along the
// shared borders and simplified with its outer border locked. A border of a level is interior at
// the next, so seams do not stay frozen; the outer border never moves, so any mix of levels
// fits together without cracks. Small whole segments that keep a parent over its target are left
// out of it (smallest first), their bounded distance added to its error.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/tiling/chunk_grid.h"
#include "lodforge/tiling/chunk_store.h"

namespace lodforge {

struct OctreeOptions {
  // Share of its children's triangles a parent keeps (the paper's reduction factor 0.2: each
  // level keeps a fifth, i.e. removes four fifths; docs/tiles.md).
  double reduction = 0.2;
  // Largest angle a collapse may turn a face by (the paper's normal deviation, default 30).
  double maxNormalDeviationDegrees = 30;
  // Levels above the leaves (0: up to a single root).
  int levels = 0;
  // Surface samples per mesh for the geometric error (Hausdorff by sampling).
  std::uint32_t errorSamples = 10'000;
  int threads = 0;  // 0: all allowed by the process limit
  // Bytes the nodes being built at once may take (0: no limit): fewer run in parallel.
  std::uint64_t memoryBudget = 0;
  bool keepInMemory = false;  // node meshes stay in memory instead of work files
  // Nodes finished by an earlier, interrupted run (their mesh file and a summary beside it)
  // are taken as they are: the sink is not called for them again.
  bool resume = false;
  std::string workDirectory;
  // In a job of several ranks (docs/distributed.md): build only this rank's nodes of `round`
  // (octree_share.h), taking the children they need from the earlier rounds (with `resume`).
  // Rank 0 then gathers the finished tree in a call with `ranks` 1 and `resume`.
  int rank = 0, ranks = 1, round = 0;
  bool quiet = false;  // no progress of its own (a job's rank 0 shows the whole job's)
};

struct OctreeNode {
  int level = 0;              // 0: a leaf (one chunk)
  ChunkCell cell;             // the node's cell at its level (a leaf cell shifted right by level)
  Aabbd bounds;               // its content and every descendant's (tight: union of mesh bounds)
  double geometricError = 0;  // metres (model units): Hausdorff to the finest geometry, bound
  std::uint64_t triangles = 0;
  std::uint64_t lockedVertices = 0;  // border vertices its simplification had to keep
  std::uint64_t vertices = 0;
  std::uint64_t droppedSegments = 0;    // small whole segments left out of this (parent) tile
  std::vector<std::uint32_t> children;  // indices into OctreeResult::nodes
  std::vector<std::uint32_t> features;  // the input objects (parts) its mesh holds, ascending
  std::string meshPath;                 // the node's mesh in the work directory
};

struct OctreeResult {
  std::vector<OctreeNode> nodes;  // leaves first, then level by level; the root last
  std::uint32_t root = 0;
  int levels = 0;  // levels above the leaves
  // With ranks > 1: the subtrees' level and each rank's work (leaf triangles under its
  // subtrees).
  int splitLevel = 0;
  std::vector<std::uint64_t> rankWork;
};

// Called once per node, from any thread, with its finished mesh (before the parent is built).
using NodeSink = std::function<Status(const OctreeNode&, const MeshPart&)>;

// In a job of several ranks: the rounds, and the nodes of the whole tree and of this rank's
// share in each round (what buildOctree with the same chunks and options builds), for the job's
// progress.
struct ShareCounts {
  int rounds = 0;
  std::uint64_t nodes = 0;
  std::vector<std::uint64_t> mine;  // per round
};
ShareCounts countShare(const ChunkWriter& chunks, const OctreeOptions& options);

Result<OctreeResult> buildOctree(const ChunkWriter& chunks, const OctreeOptions& options,
                                 const NodeSink& sink);

}  // namespace lodforge
