// Kernel throughput: the mesh utilities and readers/writers on real and generated data.
// Run: build/release/bench/bench_kernels (or `make bench`).
#include <benchmark/benchmark.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>

#include <tbb/task_arena.h>

#include "lodforge/core/distance.h"
#include "lodforge/core/mesh.h"
#include "lodforge/core/random.h"
#include "lodforge/generate/scan.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/mesh/obj_reader.h"
#include "lodforge/io/mesh/ply_reader.h"
#include "lodforge/io/mesh/ply_writer.h"
#include "lodforge/io/mesh/vertex_codec.h"
#include "lodforge/points/cluster.h"
#include "lodforge/points/partition.h"
#include "lodforge/simplify/progressive.h"

namespace lodforge {
namespace {

// A scanned surface of `triangles` triangles as a triangle soup (3 vertices per triangle).
struct Soup {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;  // the welded mesh's indices
  std::vector<Vec3f> welded;
};

const Soup& scanSoup() {
  static const Soup soup = [] {
    const std::string path =
        (std::filesystem::temp_directory_path() / "lodforge-bench-scan.ply").string();
    if (!generateScan({.triangles = 1'000'000}, path).ok()) std::abort();
    Result<Model> model = readPly(path);
    std::filesystem::remove(path);
    Soup s;
    s.welded = model->positions;
    s.indices = model->indices;
    for (std::uint32_t i : model->indices) s.positions.push_back(model->positions[i]);
    return s;
  }();
  return soup;
}

void BM_WeldExact(benchmark::State& state) {
  const Soup& soup = scanSoup();
  std::vector<std::uint32_t> remap(soup.positions.size());
  for (auto _ : state) benchmark::DoNotOptimize(weldVertices(soup.positions, {}, {}, {}, remap));
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(soup.positions.size()));
}
BENCHMARK(BM_WeldExact)->Unit(benchmark::kMillisecond);

void BM_WeldEpsilon(benchmark::State& state) {
  const Soup& soup = scanSoup();
  std::vector<std::uint32_t> remap(soup.positions.size());
  WeldOptions options;
  options.epsilon = 1e-3f;
  for (auto _ : state)
    benchmark::DoNotOptimize(weldVertices(soup.positions, {}, {}, options, remap));
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(soup.positions.size()));
}
BENCHMARK(BM_WeldEpsilon)->Unit(benchmark::kMillisecond);

void BM_VertexNormals(benchmark::State& state) {
  const Soup& soup = scanSoup();
  std::vector<Vec3f> normals(soup.welded.size());
  for (auto _ : state) computeVertexNormals(soup.welded, soup.indices, normals);
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(soup.indices.size() / 3));
}
BENCHMARK(BM_VertexNormals)->Unit(benchmark::kMillisecond);

void BM_ConnectedComponents(benchmark::State& state) {
  const Soup& soup = scanSoup();
  std::vector<std::uint32_t> labels(soup.indices.size() / 3);
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        connectedComponents(std::uint32_t(soup.welded.size()), soup.indices, labels));
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(labels.size()));
}
BENCHMARK(BM_ConnectedComponents)->Unit(benchmark::kMillisecond);

void BM_ReadPly(benchmark::State& state) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "lodforge-bench-read.ply").string();
  if (!generateScan({.triangles = 1'000'000}, path).ok()) std::abort();
  const auto bytes = std::filesystem::file_size(path);
  for (auto _ : state) benchmark::DoNotOptimize(readPly(path));
  state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(bytes));
  std::filesystem::remove(path);
}
BENCHMARK(BM_ReadPly)->Unit(benchmark::kMillisecond);

void BM_ReadObjBunny(benchmark::State& state) {
  const std::string path = std::string(LODFORGE_DATA_DIR) + "/meshes/stanford-bunny.obj";
  const auto bytes = std::filesystem::file_size(path);
  for (auto _ : state) benchmark::DoNotOptimize(readObj(path));
  state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(bytes));
}
BENCHMARK(BM_ReadObjBunny)->Unit(benchmark::kMillisecond);

void BM_WriteGlb(benchmark::State& state) {
  const Soup& soup = scanSoup();
  Model model;
  ModelBuilder builder(model);
  builder.beginObject("scan");
  model.positions = soup.welded;
  model.indices = soup.indices;
  builder.endObject();
  const std::string path = (std::filesystem::temp_directory_path() / "lodforge-bench.glb").string();
  for (auto _ : state) {
    if (!writeGlb(model, path).ok()) std::abort();
  }
  state.SetBytesProcessed(std::int64_t(state.iterations()) *
                          std::int64_t(std::filesystem::file_size(path)));
  std::filesystem::remove(path);
}
BENCHMARK(BM_WriteGlb)->Unit(benchmark::kMillisecond);

// One block of the point pipeline (50,000 points of a wavy, noisy terrain, no normals): the
// clustering tree with normals, spacing, radii and errors, on one thread.
void BM_ClusterBlock(benchmark::State& state) {
  Random random(11);
  std::vector<CloudPoint> block(50'000);
  for (CloudPoint& p : block) {
    const double x = random.uniform(0, 100), y = random.uniform(0, 100);
    p.position = {x, y, 3 * std::sin(x / 9) * std::cos(y / 7) + random.uniform(-0.02, 0.02)};
  }
  // Arg 1: as tiles call it (no node colours, ids moved with the points, first points kept).
  const bool tiles = state.range(0) == 1;
  ClusterOptions options;
  options.colors = !tiles;
  tbb::task_arena one(1);
  for (auto _ : state) {
    std::vector<CloudPoint> points = block;
    std::vector<std::uint32_t> ids(tiles ? block.size() : 0), firstPoint;
    std::iota(ids.begin(), ids.end(), 0u);
    one.execute([&] {
      benchmark::DoNotOptimize(
          clusterBlock(points, {50, 50, 0}, false, options, tiles ? &firstPoint : nullptr, ids));
    });
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(block.size()));
}
BENCHMARK(BM_ClusterBlock)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// One in-memory split of a node's points at the centroid plane (random points: the side of each
// is a coin toss): splitPoints (Arg 0) against std::partition, the plain Hoare scan that leaves
// the same order (Arg 1).
void BM_SplitPoints(benchmark::State& state) {
  Random random(5);
  std::vector<CloudPoint> node(4'000'000);
  for (CloudPoint& p : node) p.position = {random.uniform(0, 1), random.uniform(0, 1), 0};
  std::vector<CloudPoint> points(node.size());
  for (auto _ : state) {
    state.PauseTiming();
    points = node;
    state.ResumeTiming();
    if (state.range(0) == 0) {
      benchmark::DoNotOptimize(splitPoints(points, {0, 0.5}));
    } else {
      benchmark::DoNotOptimize(std::partition(
          points.begin(), points.end(), [](const CloudPoint& p) { return p.position.x < 0.5; }));
    }
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(node.size()));
}
BENCHMARK(BM_SplitPoints)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// EXT_meshopt_compression's attribute stream of the 1 M-triangle scan's welded vertices as a
// quantised tile holds them (16-bit positions padded to 8 bytes): our encoder (Arg 0) and
// meshoptimizer's (Arg 1), the same bytes.
void BM_EncodeVertexAttributes(benchmark::State& state) {
  const Soup& soup = scanSoup();
  Aabb box = computeBounds(soup.welded);
  std::vector<std::uint16_t> quantized;
  for (const Vec3f& p : soup.welded) {
    for (int a = 0; a < 3; ++a)
      quantized.push_back(static_cast<std::uint16_t>(65535.0f * (p[a] - box.min[a]) /
                                                     std::max(box.max[a] - box.min[a], 1e-9f)));
    quantized.push_back(0);
  }
  const std::size_t count = soup.welded.size(), stride = 8;
  std::vector<std::byte> out(std::max(vertexAttributesBound(count, stride),
                                      meshopt_encodeVertexBufferBound(count, stride)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        state.range(0) == 0
            ? encodeVertexAttributes(out, quantized.data(), count, stride)
            : meshopt_encodeVertexBuffer(reinterpret_cast<unsigned char*>(out.data()), out.size(),
                                         quantized.data(), count, stride));
  }
  state.SetBytesProcessed(std::int64_t(state.iterations()) * std::int64_t(count * stride));
}
BENCHMARK(BM_EncodeVertexAttributes)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// A parent tile's error as `tiles` measures it (simplify_node.cpp): a 200 K-triangle piece of a
// scan simplified to a fifth, then the sampled Hausdorff distance between the two with 10,000
// samples a side (Arg 0), or only the two grids built (Arg 1).
struct NodePair {
  std::vector<Vec3f> positions, keptPositions;
  std::vector<std::uint32_t> indices, keptIndices;
};

const NodePair& nodePair() {
  static const NodePair pair = [] {
    const std::string path =
        (std::filesystem::temp_directory_path() / "lodforge-bench-node.ply").string();
    if (!generateScan({.triangles = 200'000}, path).ok()) std::abort();
    Result<Model> model = readPly(path);
    std::filesystem::remove(path);
    if (!model) std::abort();
    NodePair p;
    p.positions = model->positions;
    p.indices = model->indices;
    const SimplifiedMesh kept = simplifyMesh(
        p.positions, p.indices,
        {.minNormalCos = 0.866, .stopAtTriangles = std::uint32_t(p.indices.size() / 15)});
    for (std::uint32_t v : kept.vertices) p.keptPositions.push_back(p.positions[v]);
    p.keptIndices = kept.indices;
    return p;
  }();
  return pair;
}

void BM_NodeError(benchmark::State& state) {
  const NodePair& p = nodePair();
  for (auto _ : state) {
    if (state.range(0) == 0) {
      benchmark::DoNotOptimize(sampledHausdorff(p.keptPositions, p.keptIndices, p.positions,
                                                p.indices, 10'000, 7, false));
    } else {
      const NearestTriangles all(p.positions, p.indices), kept(p.keptPositions, p.keptIndices);
      benchmark::DoNotOptimize(&all);
      benchmark::DoNotOptimize(&kept);
    }
  }
}
BENCHMARK(BM_NodeError)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// A parent tile's simplification, one thread: the 200 K-triangle piece of a scan to a fifth of
// its triangles with the tiles' options (30 degrees, rims free to move) by our simplifier
// (Arg 0), and by meshopt_simplify with its borders locked (Arg 1).
void BM_NodeSimplify(benchmark::State& state) {
  const NodePair& p = nodePair();
  const auto target = static_cast<std::uint32_t>(p.indices.size() / 15);
  std::vector<std::uint32_t> out(p.indices.size());
  tbb::task_arena one(1);
  for (auto _ : state) {
    one.execute([&] {
      if (state.range(0) == 0) {
        benchmark::DoNotOptimize(simplifyMesh(
            p.positions, p.indices,
            {.minNormalCos = 0.866, .stopAtTriangles = target, .collapseBorders = true}));
      } else {
        benchmark::DoNotOptimize(meshopt_simplify(
            out.data(), p.indices.data(), p.indices.size(), &p.positions[0].x, p.positions.size(),
            sizeof(Vec3f), 3 * std::size_t{target}, 1e30f, meshopt_SimplifyLockBorder, nullptr));
      }
    });
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(p.indices.size() / 3));
}
BENCHMARK(BM_NodeSimplify)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace lodforge

BENCHMARK_MAIN();
