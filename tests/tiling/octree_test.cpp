#include "lodforge/tiling/octree.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <thread>

#include <gtest/gtest.h>

#include "lodforge/core/distance.h"
#include "lodforge/core/mesh.h"
#include "lodforge/core/random.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "lodforge/io/model_io.h"
#include "lodforge/tiles/surface_input.h"
#include "test_support.h"

namespace lodforge {
namespace {

namespace fs = std::filesystem;

// A wavy open surface: its rim is the only boundary.
MeshPart heightfield(int n) {
  MeshPart mesh;
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= n; ++x) {
      const double z =
          0.8 * std::sin(x * 0.21) * std::cos(y * 0.17) + 0.05 * std::sin(x * y * 0.01);
      mesh.positions.push_back({1000.0 + x, 2000.0 + y, z});
    }
  }
  const auto at = [n](int x, int y) { return static_cast<std::uint32_t>(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      mesh.indices.insert(mesh.indices.end(), {at(x, y), at(x + 1, y), at(x + 1, y + 1)});
      mesh.indices.insert(mesh.indices.end(), {at(x, y), at(x + 1, y + 1), at(x, y + 1)});
    }
  }
  return mesh;
}

MeshPart horse() {
  Result<Model> model = readModel(test::dataPath("meshes/horse.ply"));
  EXPECT_TRUE(model.ok());
  MeshPart mesh;
  for (const Vec3f& p : model->positions) mesh.positions.push_back(model->origin + toDouble(p));
  mesh.indices = model->indices;
  weldExact(mesh);
  return mesh;
}

using Edge = std::pair<Vec3d, Vec3d>;
struct EdgeLess {
  static bool less(const Vec3d& a, const Vec3d& b) {
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
  }
  bool operator()(const Edge& a, const Edge& b) const {
    if (a.first != b.first) return less(a.first, b.first);
    return less(a.second, b.second);
  }
};

// Boundary edges as position pairs (smaller end first).
std::set<Edge, EdgeLess> boundaryEdges(MeshPart mesh) {
  weldExact(mesh);
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = mesh.indices[t + k], b = mesh.indices[t + (k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::set<Edge, EdgeLess> out;
  for (const auto& [edge, count] : uses) {
    if (count != 1) continue;
    Vec3d a = mesh.positions[edge.first], b = mesh.positions[edge.second];
    if (EdgeLess::less(b, a)) std::swap(a, b);
    out.insert({a, b});
  }
  return out;
}

struct Built {
  OctreeResult tree;
  std::map<std::uint32_t, MeshPart> meshes;  // by node index... filled through the cell key
};

// The heightfield with small closed cubes floating above it: whole segments (CAD-like parts).
MeshPart heightfieldWithCubes(int n, int cubes, std::uint64_t seed) {
  MeshPart mesh = heightfield(n);
  Random random(seed);
  for (int c = 0; c < cubes; ++c) {
    const Vec3d at{1000 + random.uniform(1, n - 1), 2000 + random.uniform(1, n - 1),
                   2 + random.uniform(0, 1)};
    const double h = random.uniform(0.1, 0.5);
    const auto first = static_cast<std::uint32_t>(mesh.positions.size());
    for (int k = 0; k < 8; ++k)
      mesh.positions.push_back(at + Vec3d{k & 1 ? h : -h, k & 2 ? h : -h, k & 4 ? h : -h});
    // Outward-facing quads (corner bits x=1, y=2, z=4), two triangles each.
    const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
      mesh.indices.insert(mesh.indices.end(), {first + q[0], first + q[1], first + q[2]});
      mesh.indices.insert(mesh.indices.end(), {first + q[0], first + q[2], first + q[3]});
    }
  }
  return mesh;
}

// `input` cut into a grid of `chunkSize` cubes, in chunk files under `directory`.
std::unique_ptr<ChunkWriter> chunksOf(const MeshPart& input, double chunkSize,
                                      const std::string& directory) {
  Aabbd box;
  for (const Vec3d& p : input.positions) box.add(p);
  auto chunks = std::make_unique<ChunkWriter>(ChunkGrid::over(box, chunkSize), directory, 1 << 20);
  for (std::size_t t = 0; t < input.indices.size(); t += 3) {
    std::array<CutCorner, 3> triangle;
    for (std::size_t k = 0; k < 3; ++k)
      triangle[k] = {input.positions[input.indices[t + k]], {255, 255, 255, 255}, {0, 0, 1}};
    EXPECT_TRUE(chunks->addTriangle(triangle).ok());
  }
  EXPECT_TRUE(chunks->flush().ok());
  return chunks;
}

Built buildOver(const ChunkWriter& chunks, const OctreeOptions& base, const std::string& work);

// Cuts `input` into a grid and builds the octree, keeping every node's mesh. With `segments`,
// the input's connected components smaller than a chunk go in whole, as chunkInput does.
Built build(const MeshPart& input, double chunkSize, const OctreeOptions& base,
            const std::string& work, bool segments = false) {
  fs::remove_all(work);
  fs::create_directories(work + "/nodes");
  Aabbd box;
  for (const Vec3d& p : input.positions) box.add(p);
  ChunkWriter chunks(ChunkGrid::over(box, chunkSize), work + "/chunks", 1 << 20);
  std::vector<std::uint32_t> component(input.triangleCount(), 0);
  std::vector<Aabbd> segmentBounds(1);
  if (segments) {
    segmentBounds.resize(connectedComponents(input.vertexCount(), input.indices, component));
    for (std::size_t i = 0; i < input.indices.size(); ++i)
      segmentBounds[component[i / 3]].add(input.positions[input.indices[i]]);
  }
  for (std::size_t t = 0; t < input.indices.size(); t += 3) {
    std::array<CutCorner, 3> triangle;
    for (std::size_t k = 0; k < 3; ++k)
      triangle[k] = {input.positions[input.indices[t + k]], {255, 255, 255, 255}, {0, 0, 1}};
    EXPECT_TRUE((segments ? chunks.addSegmentTriangle(segmentBounds[component[t / 3]], triangle)
                          : chunks.addTriangle(triangle))
                    .ok());
  }
  EXPECT_TRUE(chunks.flush().ok());
  return buildOver(chunks, base, work);
}

// The octree over chunks already made, keeping every node's mesh.
Built buildOver(const ChunkWriter& chunks, const OctreeOptions& base, const std::string& work) {
  fs::create_directories(work + "/nodes");
  OctreeOptions options = base;
  options.workDirectory = work + "/nodes";
  std::mutex mutex;
  std::map<std::string, MeshPart> byPath;
  Result<OctreeResult> tree =
      buildOctree(chunks, options, [&](const OctreeNode& node, const MeshPart& mesh) -> Status {
        std::lock_guard lock(mutex);
        byPath[node.meshPath] = mesh;
        return {};
      });
  EXPECT_TRUE(tree.ok()) << (tree.ok() ? "" : tree.error().message);
  Built built{std::move(*tree), {}};
  for (std::uint32_t i = 0; i < built.tree.nodes.size(); ++i) {
    const auto it = byPath.find(built.tree.nodes[i].meshPath);
    if (it != byPath.end()) built.meshes[i] = it->second;
  }
  return built;
}

// A random cut through the tree: each node with children is refined with probability 1/2.
void randomMix(const Built& built, std::uint32_t node, Random& random,
               std::vector<std::uint32_t>& selected) {
  const OctreeNode& n = built.tree.nodes[node];
  const bool hasMesh = built.meshes.count(node) != 0;
  if (!n.children.empty() && (!hasMesh || random.uniform(0, 1) < 0.5)) {
    for (std::uint32_t c : n.children) randomMix(built, c, random, selected);
  } else {
    selected.push_back(node);
  }
}

// Boundary edges of a mix with an end off the input's rim (the finest level's boundary
// vertices): a crack. Rims themselves may simplify, so a rim edge of a coarse tile can join two
// rim vertices the finest level does not join directly.
std::size_t edgesOffTheRim(const std::set<Edge, EdgeLess>& edges,
                           const std::set<Vec3d, bool (*)(const Vec3d&, const Vec3d&)>& rim) {
  std::size_t off = 0;
  for (const Edge& e : edges) off += rim.count(e.first) == 0 || rim.count(e.second) == 0 ? 1 : 0;
  return off;
}

std::set<Vec3d, bool (*)(const Vec3d&, const Vec3d&)> endsOf(
    const std::set<Edge, EdgeLess>& edges) {
  std::set<Vec3d, bool (*)(const Vec3d&, const Vec3d&)> ends(&EdgeLess::less);
  for (const Edge& e : edges) ends.insert(e.first), ends.insert(e.second);
  return ends;
}

// 40 random mixes of levels, each assembled and checked for edges off the rim.
void expectNoCracks(const Built& built,
                    const std::set<Vec3d, bool (*)(const Vec3d&, const Vec3d&)>& rim,
                    std::uint64_t seed, const std::string& what) {
  Random random(seed);
  for (int mix = 0; mix < 40; ++mix) {
    std::vector<std::uint32_t> selected;
    randomMix(built, built.tree.root, random, selected);
    std::vector<MeshPart> parts;
    for (std::uint32_t s : selected) parts.push_back(built.meshes.at(s));
    EXPECT_EQ(edgesOffTheRim(boundaryEdges(concatenate(parts)), rim), 0u)
        << what << ", mix " << mix << " of " << selected.size() << " tiles";
  }
}

TEST(Octree, AnyMixOfLevelsHasNoBoundaryTheInputDidNotHave) {
  OctreeOptions options;
  options.errorSamples = 2000;
  for (const bool open : {true, false}) {
    const MeshPart input = open ? heightfield(120) : horse();
    Aabbd box;
    for (const Vec3d& p : input.positions) box.add(p);
    const test::TempDir temp;  // removed with the test
    const Built built = build(input, box.longestSide() / 7.5, options, temp.file("octree-mix"));
    ASSERT_GE(built.tree.levels, 2);
    const std::set<Edge, EdgeLess> original = boundaryEdges(input);
    // The input's rim, cut at the chunk planes, is made of pieces of the original edges: compare
    // against the finest level's boundary (all leaves), which must itself lie on the rim.
    std::vector<MeshPart> leaves;
    for (const auto& [index, mesh] : built.meshes)
      if (built.tree.nodes[index].level == 0) leaves.push_back(mesh);
    const std::set<Edge, EdgeLess> finest = boundaryEdges(concatenate(leaves));
    EXPECT_EQ(finest.empty(), original.empty());
    for (const Edge& e : finest) {  // the heightfield's rim: x or y at the grid's ends
      for (const Vec3d& p : {e.first, e.second}) {
        EXPECT_TRUE(p.x == 1000 || p.x == 1120 || p.y == 2000 || p.y == 2120) << p.x << " " << p.y;
      }
    }
    expectNoCracks(built, endsOf(finest), open ? 7 : 8, open ? "heightfield" : "horse");
    // The rim simplifies too (only the tiles' outer faces are locked): the root keeps few of it.
    const std::size_t rootRim = boundaryEdges(built.meshes.at(built.tree.root)).size();
    if (open) {
      EXPECT_LT(rootRim, finest.size() / 4);
    } else {
      EXPECT_EQ(rootRim, 0u);
    }
  }
}

// A surface reconstructed from points straight into the leaves (tiles/surface_input, the
// paper's "Chunk" path: an open wavy sheet with its own edge, chunks of 11 voxels, near the
// origin where chunk planes and lattice corners round apart): no mix of levels opens a crack.
TEST(Octree, AReconstructedScanHasNoCrackInAnyMix) {
  Random random(3);
  PlyLayout layout;
  layout.vertexCount = 12'000;
  std::vector<Vec3f> points;
  for (std::size_t i = 0; i < layout.vertexCount; ++i) {
    const double x = random.uniform(0, 80), y = random.uniform(0, 50);
    points.push_back(toFloat(Vec3d{x, y, 3 * std::sin(x / 9) * std::cos(y / 7)}));
  }
  const test::TempDir temp;  // removed with the test
  const std::string work = temp.file("octree-surface");
  fs::remove_all(work);
  fs::create_directories(work);
  Result<PlyWriter> writer = PlyWriter::create(work + "/cloud.ply", layout);
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(writer->writeVertices(points, {}, {}).ok());
  ASSERT_TRUE(writer->finish().ok());
  ReconstructOptions reconstruct;
  reconstruct.normals.orientation = NormalOrientation::kUp;
  reconstruct.chunkVoxels = 11;
  ChunkInputOptions input;
  input.workDirectory = work;
  ReconstructStats stats;
  Result<ChunkInput> chunks = surfaceChunkInput(work + "/cloud.ply", input, reconstruct, stats);
  ASSERT_TRUE(chunks.ok()) << chunks.error().message;
  OctreeOptions options;
  options.errorSamples = 2000;
  const Built built = buildOver(*chunks->chunks, options, work);
  ASSERT_GE(built.tree.levels, 2);
  std::vector<MeshPart> leaves;
  for (const auto& [index, mesh] : built.meshes)
    if (built.tree.nodes[index].level == 0) leaves.push_back(mesh);
  EXPECT_EQ(concatenate(leaves).triangleCount(), stats.triangles);
  expectNoCracks(built, endsOf(boundaryEdges(concatenate(leaves))), 9, "reconstructed sheet");
}

TEST(Octree, ParentsAreSimplerAndTheirErrorBoundsTheirChildren) {
  OctreeOptions options;
  options.errorSamples = 4000;
  const MeshPart input = heightfield(160);
  const test::TempDir temp;  // removed with the test
  const Built built = build(input, 20, options, temp.file("octree-error"));
  ASSERT_GE(built.tree.levels, 2);
  std::uint64_t leafTriangles = 0;
  for (const OctreeNode& node : built.tree.nodes) {
    if (node.level == 0) {
      EXPECT_EQ(node.geometricError, 0.0);
      leafTriangles += node.triangles;
      continue;
    }
    std::uint64_t childTriangles = 0;
    for (std::uint32_t c : node.children) {
      const OctreeNode& child = built.tree.nodes[c];
      EXPECT_GE(node.geometricError, child.geometricError);
      childTriangles += child.triangles;
      for (int axis = 0; axis < 3; ++axis) {
        EXPECT_LE(node.bounds.min[axis], child.bounds.min[axis]);
        EXPECT_GE(node.bounds.max[axis], child.bounds.max[axis]);
      }
    }
    EXPECT_LT(node.triangles, childTriangles);  // simplified
    EXPECT_GT(node.geometricError, 0.0);
    EXPECT_GT(node.lockedVertices, 0u);  // its outer border
  }
  const OctreeNode& root = built.tree.nodes[built.tree.root];
  EXPECT_LT(root.triangles, leafTriangles / 4);
  // The root's own error, measured directly against the input, stays under its bound.
  const MeshPart& rootMesh = built.meshes.at(built.tree.root);
  const Vec3d center = root.bounds.center();
  std::vector<Vec3f> a, b;
  for (const Vec3d& p : rootMesh.positions) a.push_back(toFloat(p - center));
  for (const Vec3d& p : input.positions) b.push_back(toFloat(p - center));
  const SurfaceDistance direct = surfaceDistance(a, rootMesh.indices, b, input.indices, 20000);
  EXPECT_LE(direct.hausdorff, root.geometricError * 1.05 + 1e-6);
}

void leafVertices(const Built& built, std::uint32_t node, std::vector<Vec3d>& out) {
  const OctreeNode& n = built.tree.nodes[node];
  if (n.level == 0) {
    const MeshPart& mesh = built.meshes.at(node);
    out.insert(out.end(), mesh.positions.begin(), mesh.positions.end());
  }
  for (std::uint32_t c : n.children) leafVertices(built, c, out);
}

TEST(Octree, SmallSegmentsLeaveCoarseTilesWithinTheErrorAndWithoutCracks) {
  // 400 closed cubes above a surface: they cannot simplify below a few triangles each, so the
  // parents leave the smallest out to keep their reduction. No mix of levels opens a boundary,
  // the pyramid still shrinks, and every leaf vertex under a parent is within the parent's
  // geometric error of its mesh (a dropped cube floats 2-3 units above the surface: without
  // its share in the error this fails).
  OctreeOptions options;
  options.errorSamples = 2000;
  const MeshPart input = heightfieldWithCubes(120, 400, 3);
  const test::TempDir temp;  // removed with the test
  const Built built = build(input, 16, options, temp.file("octree-cubes"), true);
  ASSERT_GE(built.tree.levels, 2);
  std::uint64_t dropped = 0, leafTriangles = 0;
  for (const OctreeNode& node : built.tree.nodes) {
    dropped += node.droppedSegments;
    if (node.level == 0) leafTriangles += node.triangles;
  }
  EXPECT_GE(leafTriangles, input.triangleCount());  // the surface is cut, the cubes are not
  EXPECT_GT(dropped, 100u);
  const OctreeNode& root = built.tree.nodes[built.tree.root];
  EXPECT_LT(root.triangles, leafTriangles / 10);
  for (std::uint32_t i = 0; i < built.tree.nodes.size(); ++i) {
    const OctreeNode& node = built.tree.nodes[i];
    if (node.level == 0) continue;
    std::vector<Vec3d> finest;
    leafVertices(built, i, finest);
    const Vec3d center = node.bounds.center();
    std::vector<Vec3f> points, positions;
    for (const Vec3d& p : finest) points.push_back(toFloat(p - center));
    const MeshPart& mesh = built.meshes.at(i);
    for (const Vec3d& p : mesh.positions) positions.push_back(toFloat(p - center));
    EXPECT_LE(farthestDistance(points, positions, mesh.indices), node.geometricError + 1e-5)
        << "level " << node.level;
  }
  // Closed cubes and a cut surface: any mix has only the surface's rim as boundary.
  std::vector<MeshPart> leaves;
  for (const auto& [index, mesh] : built.meshes)
    if (built.tree.nodes[index].level == 0) leaves.push_back(mesh);
  expectNoCracks(built, endsOf(boundaryEdges(concatenate(leaves))), 11, "cubes");
}

TEST(Octree, LevelsOptionStopsBelowTheRootWithAContentlessRoot) {
  OctreeOptions options;
  options.errorSamples = 1000;
  options.levels = 1;
  const test::TempDir temp;  // removed with the test
  const Built built = build(heightfield(100), 12, options, temp.file("octree-lv"));
  EXPECT_EQ(built.tree.levels, 1);
  const OctreeNode& root = built.tree.nodes[built.tree.root];
  EXPECT_GT(root.children.size(), 1u);
  EXPECT_TRUE(root.meshPath.empty());
  for (std::uint32_t c : root.children)
    EXPECT_GE(root.geometricError, built.tree.nodes[c].geometricError);
}

TEST(Octree, NodesFollowTheirChildrenWithinTheBudgetAndTheTreeIsTheSameForAnySchedule) {
  // Nodes start as soon as their children are done, across levels; a budget that fits one
  // node at a time keeps them one at a time; and whatever the schedule, the same tree.
  const MeshPart input = heightfield(120);
  struct Run {
    std::vector<OctreeNode> nodes;
    std::map<std::string, MeshPart> meshes;
    int mostAtOnce = 0;
  };
  const auto run = [&](int threads, std::uint64_t budget, const std::string& name) {
    const test::TempDir temp;  // removed with the test
    const std::string work = temp.file("octree-schedule-") + name;
    fs::remove_all(work);
    const std::unique_ptr<ChunkWriter> chunks = chunksOf(input, 10, work + "/chunks");
    OctreeOptions options;
    options.errorSamples = 500;
    options.threads = threads;
    options.memoryBudget = budget;
    options.workDirectory = work + "/nodes";
    fs::create_directories(options.workDirectory);
    Run out;
    std::mutex mutex;
    std::atomic<int> atOnce = 0;
    std::set<std::string> done;
    Result<OctreeResult> tree =
        buildOctree(*chunks, options, [&](const OctreeNode& node, const MeshPart& mesh) -> Status {
          const int now = ++atOnce;
          std::this_thread::sleep_for(std::chrono::milliseconds(5));  // let others overlap
          std::lock_guard lock(mutex);
          out.mostAtOnce = std::max(out.mostAtOnce, now);
          out.meshes[node.meshPath.substr(node.meshPath.rfind('/'))] = mesh;
          done.insert(node.meshPath);
          --atOnce;
          return {};
        });
    EXPECT_TRUE(tree.ok());
    if (!tree.ok()) return out;
    // Work files go as soon as nothing needs them: every chunk, every mesh but the root's; the
    // summaries stay (a resumed run reads them).
    std::size_t meshes = 0, summaries = 0;
    for (const auto& entry : fs::directory_iterator(options.workDirectory)) {
      meshes += entry.path().extension() == ".mesh" ? 1 : 0;
      summaries += entry.path().extension() == ".json" ? 1 : 0;
    }
    EXPECT_EQ(meshes, 1u);
    EXPECT_EQ(summaries, tree->nodes.size());
    EXPECT_TRUE(fs::is_empty(work + "/chunks"));
    for (const OctreeNode& node : tree->nodes) {
      for (std::uint32_t c : node.children) EXPECT_EQ(done.count(tree->nodes[c].meshPath), 1u);
    }
    out.nodes = std::move(tree->nodes);
    return out;
  };
  const Run one = run(1, 0, "one"), two = run(2, 0, "two"), tight = run(2, 1, "tight");
  EXPECT_EQ(one.mostAtOnce, 1);
  EXPECT_LE(two.mostAtOnce, 2);
  EXPECT_EQ(tight.mostAtOnce, 1);  // the budget holds one node, so one runs at a time
  ASSERT_GT(one.nodes.size(), 20u);
  for (const Run* other : {&two, &tight}) {
    ASSERT_EQ(other->nodes.size(), one.nodes.size());
    for (std::size_t i = 0; i < one.nodes.size(); ++i) {
      EXPECT_EQ(other->nodes[i].geometricError, one.nodes[i].geometricError) << i;
      EXPECT_EQ(other->nodes[i].triangles, one.nodes[i].triangles) << i;
    }
    ASSERT_EQ(other->meshes.size(), one.meshes.size());
    for (const auto& [name, mesh] : one.meshes) {
      EXPECT_EQ(other->meshes.at(name).indices, mesh.indices) << name;
      EXPECT_EQ(other->meshes.at(name).positions, mesh.positions) << name;
    }
  }
}

TEST(Octree, AResumedBuildSkipsFinishedNodesWhoseWorkFilesAreGone) {
  // A run stopped at its root (the sink fails there): every other node is finished and the
  // meshes below level 1 are already removed. Resumed, only the root is built, the same as
  // in an uninterrupted run.
  const MeshPart input = heightfield(100);
  const test::TempDir temp;  // removed with the test
  const std::string work = temp.file("octree-resume");
  fs::remove_all(work);
  const std::unique_ptr<ChunkWriter> chunks = chunksOf(input, 10, work + "/chunks");
  OctreeOptions options;
  options.errorSamples = 500;
  const Built whole = build(input, 10, options, work + "-whole");
  const int rootLevel = whole.tree.nodes[whole.tree.root].level;
  ASSERT_GE(rootLevel, 2);
  options.threads = 2;
  options.workDirectory = work + "/nodes";
  fs::create_directories(options.workDirectory);
  Result<OctreeResult> stopped =
      buildOctree(*chunks, options, [&](const OctreeNode& node, const MeshPart&) -> Status {
        if (node.level == rootLevel) return Error{ErrorKind::kCancelled, "stopped"};
        return {};
      });
  ASSERT_FALSE(stopped.ok());
  options.resume = true;
  std::vector<int> built;
  MeshPart root;
  Result<OctreeResult> resumed =
      buildOctree(*chunks, options, [&](const OctreeNode& node, const MeshPart& mesh) -> Status {
        built.push_back(node.level);
        root = mesh;
        return {};
      });
  ASSERT_TRUE(resumed.ok()) << resumed.error().message;
  ASSERT_EQ(built.size(), 1u);  // the root alone
  EXPECT_EQ(built[0], resumed->nodes[resumed->root].level);
  // The same root as an uninterrupted build.
  EXPECT_EQ(root.indices, whole.meshes.at(whole.tree.root).indices);
  EXPECT_EQ(root.positions, whole.meshes.at(whole.tree.root).positions);
  EXPECT_EQ(resumed->nodes[resumed->root].geometricError,
            whole.tree.nodes[whole.tree.root].geometricError);
}

}  // namespace
}  // namespace lodforge
