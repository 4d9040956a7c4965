#include "lodforge/runtime/stream.h"

#include <algorithm>
#include <numeric>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "lodforge/runtime/path.h"
#include "lodforge/runtime/selection.h"
#include "lodforge/simplify/reform.h"
#include "packages.h"

namespace lodforge {
namespace {

// The buffer for a selection built from nothing, object by object, with the single-object
// reformation kernel: what every streamed frame must equal.
struct Reference {
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<std::uint32_t> source, indices;

  Reference(const Package& package, std::span<const std::uint32_t> vc,
            std::span<const std::uint32_t> tc) {
    for (std::size_t i = 0; i < vc.size(); ++i) {
      const auto base = static_cast<std::uint32_t>(positions.size());
      const auto take = [&](auto all, auto& into) {
        if (!all.empty()) into.insert(into.end(), all.begin(), all.begin() + vc[i]);
      };
      take(package.positions(i), positions);
      take(package.normals(i), normals);
      take(package.colors(i), colors);
      const auto triangles = package.triangles(i).first(3 * std::size_t{tc[i]});
      source.insert(source.end(), triangles.begin(), triangles.end());
      std::vector<std::uint32_t> reformed(triangles.size());
      reformObject(triangles, package.ecol(i), vc[i], base, reformed);
      indices.insert(indices.end(), reformed.begin(), reformed.end());
    }
  }
};

template <class T>
bool same(std::span<const T> a, const std::vector<T>& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
}

void expectEqualsReference(const StreamBuffer& buffer, const Package& package, const Selection& s,
                           const std::string& where) {
  const Reference r(package, s.vertexCounts, s.triangleCounts);
  ASSERT_EQ(buffer.vertexCount(), s.totalVertices) << where;
  ASSERT_EQ(buffer.triangleCount(), s.totalTriangles) << where;
  ASSERT_TRUE(same(buffer.positions(), r.positions)) << where;
  ASSERT_TRUE(same(buffer.normals(), r.normals)) << where;
  ASSERT_TRUE(same(buffer.colors(), r.colors)) << where;
  ASSERT_TRUE(same(buffer.sourceTriangles(), r.source)) << where;
  ASSERT_TRUE(same(buffer.indices(), r.indices)) << where;
  ASSERT_TRUE(std::equal(buffer.vertexCounts().begin(), buffer.vertexCounts().end(),
                         s.vertexCounts.begin()))
      << where;
}

// What a frame from `before` to `after` must report.
FrameStats expectedStats(const Package& package, std::span<const std::uint32_t> vo,
                         std::span<const std::uint32_t> to, std::span<const std::uint32_t> vn,
                         std::span<const std::uint32_t> tn) {
  FrameStats e;
  const std::uint64_t vb = StreamCapacity::vertexBytes(package);
  for (std::size_t i = 0; i < vn.size(); ++i) {
    const std::uint64_t keptV = std::min(vo[i], vn[i]), keptT = std::min(to[i], tn[i]);
    e.verticesRead += vn[i] - keptV;
    e.trianglesRead += tn[i] - keptT;
    e.bytesMoved += keptV * vb + keptT * 12;
    if (vo[i] == vn[i]) {
      e.trianglesKept += tn[i];
      e.bytesMoved += std::uint64_t{tn[i]} * 12;
    } else {
      e.trianglesReformed += tn[i];
      ++e.objectsChanged;
    }
  }
  e.bytesRead = e.verticesRead * vb + e.trianglesRead * 12;
  return e;
}

TEST(Stream, EveryFrameEqualsAFreshBuildAlongRandomPaths) {
  Random random(21);
  for (const char* key : {"engine", "motor", "horse", "cad"}) {
    const Package& package = test::RuntimePackages::get(key);
    const LodScene scene = LodScene::fromPackage(package);
    const Aabbd bounds = test::packageBounds(package);
    const std::uint64_t full = scene.totalMaxVertices();
    StreamBuffer buffer(package, StreamCapacity::forVertices(package, full));
    std::vector<Camera> path = orbitPath(bounds, {.frames = 12});
    for (const Camera& c : flyThroughPath(bounds, {.frames = 12})) path.push_back(c);
    for (int k = 0; k < 12; ++k) {  // random jumps: large changes between frames
      const Vec3d size = bounds.size();
      Camera c = Camera::lookAt(
          bounds.center() + Vec3d{random.uniform(-1, 1) * size.x, random.uniform(-1, 1) * size.y,
                                  random.uniform(-1, 1) * size.z},
          bounds.center(), {0, 0, 1}, 60, 800, 600);
      fitClipPlanes(c, bounds);
      path.push_back(c);
    }
    Selection s;
    std::vector<std::uint32_t> lastV(scene.size(), 0), lastT(scene.size(), 0);
    std::uint64_t reformed = 0, kept = 0;
    for (std::size_t f = 0; f < path.size(); ++f) {
      // The budget drifts too, as a user drags the slider.
      const auto budget = static_cast<std::uint64_t>(double(full) * random.uniform(0.02, 0.6));
      selectTwoPass(scene, path[f], budget, {}, s);
      ASSERT_EQ(s.totalVertices, std::min(budget, full));
      Result<FrameStats> stats = buffer.update(s.vertexCounts, s.triangleCounts);
      ASSERT_TRUE(stats.ok()) << stats.error().message;
      const std::string where = std::string(key) + " frame " + std::to_string(f);
      expectEqualsReference(buffer, package, s, where);
      const FrameStats e = expectedStats(package, lastV, lastT, s.vertexCounts, s.triangleCounts);
      EXPECT_EQ(stats->bytesRead, e.bytesRead) << where;
      EXPECT_EQ(stats->bytesMoved, e.bytesMoved) << where;
      EXPECT_EQ(stats->verticesRead, e.verticesRead) << where;
      EXPECT_EQ(stats->trianglesRead, e.trianglesRead) << where;
      EXPECT_EQ(stats->trianglesReformed, e.trianglesReformed) << where;
      EXPECT_EQ(stats->trianglesKept, e.trianglesKept) << where;
      EXPECT_EQ(stats->objectsChanged, e.objectsChanged) << where;
      EXPECT_EQ(stats->trianglesReformed + stats->trianglesKept, s.totalTriangles) << where;
      reformed += stats->trianglesReformed;
      kept += stats->trianglesKept;
      lastV = s.vertexCounts;
      lastT = s.triangleCounts;
    }
    // Both index paths ran.
    EXPECT_GT(reformed, 0u) << key;
    if (scene.size() > 1) {
      EXPECT_GT(kept, 0u) << key;
    }
  }
}

TEST(Stream, AnUnchangedSelectionReadsNothingAndClearReadsEverything) {
  const Package& package = test::RuntimePackages::get("engine");
  const LodScene scene = LodScene::fromPackage(package);
  StreamBuffer buffer(package, StreamCapacity::forVertices(package, scene.totalMaxVertices() / 2));
  Selection s;
  selectTwoPass(scene, orbitPath(test::packageBounds(package), {.frames = 1}).front(),
                scene.totalMaxVertices() / 2, {}, s);
  Result<FrameStats> first = buffer.update(s.vertexCounts, s.triangleCounts);
  ASSERT_TRUE(first.ok());
  EXPECT_EQ(first->verticesRead, s.totalVertices);
  EXPECT_EQ(first->bytesMoved, 0u);
  Result<FrameStats> again = buffer.update(s.vertexCounts, s.triangleCounts);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->bytesRead, 0u);
  EXPECT_EQ(again->trianglesReformed, 0u);
  EXPECT_EQ(again->trianglesKept, s.totalTriangles);
  expectEqualsReference(buffer, package, s, "unchanged");
  buffer.clear();
  Result<FrameStats> fresh = buffer.update(s.vertexCounts, s.triangleCounts);
  ASSERT_TRUE(fresh.ok());
  EXPECT_EQ(fresh->bytesRead, first->bytesRead);
  EXPECT_EQ(fresh->trianglesReformed, s.totalTriangles);
  expectEqualsReference(buffer, package, s, "after clear");
}

TEST(Stream, ASelectionBeyondCapacityIsRefusedAndTheBufferKeepsLastFrame) {
  const Package& package = test::RuntimePackages::get("motor");
  const LodScene scene = LodScene::fromPackage(package);
  const std::uint64_t capacity = scene.totalMaxVertices() / 4;
  StreamBuffer buffer(package, StreamCapacity::forVertices(package, capacity));
  const Camera camera = orbitPath(test::packageBounds(package), {.frames = 1}).front();
  Selection small, big;
  selectTwoPass(scene, camera, capacity, {}, small);
  ASSERT_TRUE(buffer.update(small.vertexCounts, small.triangleCounts).ok());
  selectTwoPass(scene, camera, capacity + 1, {}, big);
  Result<FrameStats> refused = buffer.update(big.vertexCounts, big.triangleCounts);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().kind, ErrorKind::kLimit);
  EXPECT_NE(refused.error().message.find("does not fit the stream buffer"), std::string::npos);
  expectEqualsReference(buffer, package, small, "after refusal");
}

TEST(Stream, CapacityFromMemoryFitsAndTrianglesNeverOverflow) {
  for (const char* key : {"engine", "cad"}) {
    const Package& package = test::RuntimePackages::get(key);
    for (const std::uint64_t bytes :
         {std::uint64_t{1} << 16, std::uint64_t{3} << 20, std::uint64_t{50} << 20}) {
      const StreamCapacity c = StreamCapacity::forMemory(package, bytes);
      EXPECT_LE(c.bytes(package), bytes);
      StreamCapacity more = StreamCapacity::forVertices(package, c.vertices + 1);
      EXPECT_GT(more.bytes(package), bytes) << key << " " << bytes;
    }
    // Any selection within the vertex capacity fits the triangle capacity: at every level of every
    // object, map(n) <= ratio * n.
    const double ratio = StreamCapacity::triangleRatio(package);
    for (std::size_t i = 0; i < package.objectCount(); ++i) {
      const auto map = package.map(i);
      for (std::size_t l = 0; l < map.size(); ++l)
        ASSERT_LE(double(map[l]), ratio * double(package.object(i).minVertexCount + l) + 1e-9);
    }
  }
}

}  // namespace
}  // namespace lodforge
