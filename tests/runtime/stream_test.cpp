#include "lodforge/runtime/stream.h"

#include <algorithm>
#include <numeric>

#include <gtest/gtest.h>

#include "compact_view.h"
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

// Every object's slot holds what a fresh build holds for it, and (with `checkSlots`) the slots
// do not overlap. slotOrder settles the relocations of every frame since it last ran.
void expectEqualsReference(const StreamBuffer& buffer, const Package& package, const Selection& s,
                           const std::string& where, bool checkSlots = true) {
  const Reference r(package, s.vertexCounts, s.triangleCounts);
  ASSERT_EQ(buffer.vertexCount(), s.totalVertices) << where;
  ASSERT_EQ(buffer.triangleCount(), s.totalTriangles) << where;
  ASSERT_TRUE(std::equal(buffer.vertexCounts().begin(), buffer.vertexCounts().end(),
                         s.vertexCounts.begin()))
      << where;
  ASSERT_TRUE(std::equal(buffer.triangleCounts().begin(), buffer.triangleCounts().end(),
                         s.triangleCounts.begin()))
      << where;
  if (checkSlots) {
    ASSERT_TRUE(test::slotsAreDisjoint(buffer)) << where;
  }
  const test::CompactView view = test::compactView(buffer);
  ASSERT_TRUE(same(std::span<const Vec3f>(view.positions), r.positions)) << where;
  ASSERT_TRUE(same(std::span<const Vec3f>(view.normals), r.normals)) << where;
  ASSERT_TRUE(same(std::span<const Rgba8>(view.colors), r.colors)) << where;
  ASSERT_TRUE(same(std::span<const std::uint32_t>(view.source), r.source)) << where;
  ASSERT_TRUE(same(std::span<const std::uint32_t>(view.indices), r.indices)) << where;
}

// Slots before a frame, to see which moved.
struct Slots {
  std::vector<std::uint64_t> vertexStart, triangleStart;
  explicit Slots(const StreamBuffer& b)
      : vertexStart(b.vertexStart().begin(), b.vertexStart().end()),
        triangleStart(b.triangleStart().begin(), b.triangleStart().end()) {}
};

// What moved inside the buffer: an object whose slot moved carried its kept part (vertices and
// source triangles). Without a compaction that is all that moved, and an unchanged object stays
// where it was; a compaction moves more (kept parts packed, indices rebased).
void expectMoves(const Package& package, const Slots& before, const StreamBuffer& after,
                 std::span<const std::uint32_t> vo, std::span<const std::uint32_t> to,
                 const FrameStats& stats, const std::string& where) {
  const std::uint64_t vb = StreamCapacity::vertexBytes(package);
  std::uint64_t carried = 0;
  for (std::size_t i = 0; i < vo.size(); ++i) {
    const std::uint32_t vn = after.vertexCounts()[i], tn = after.triangleCounts()[i];
    const std::uint64_t keptV = std::min(vo[i], vn), keptT = std::min(to[i], tn);
    const bool moved = after.vertexStart()[i] != before.vertexStart[i] ||
                       after.triangleStart()[i] != before.triangleStart[i];
    if (moved) carried += keptV * vb + keptT * 12;
    if (!stats.compacted && vo[i] == vn && vn > 0) {
      ASSERT_FALSE(moved) << where << " object " << i;
    }
  }
  if (stats.compacted) {
    EXPECT_GE(stats.bytesMoved, carried) << where;
  } else {
    EXPECT_EQ(stats.bytesMoved, carried) << where;
  }
}

// What a frame from `before` to `after` must report (bytes moved: expectMoves).
FrameStats expectedStats(const Package& package, std::span<const std::uint32_t> vo,
                         std::span<const std::uint32_t> to, std::span<const std::uint32_t> vn,
                         std::span<const std::uint32_t> tn) {
  FrameStats e;
  const std::uint64_t vb = StreamCapacity::vertexBytes(package);
  for (std::size_t i = 0; i < vn.size(); ++i) {
    e.verticesRead += vn[i] - std::min(vo[i], vn[i]);
    e.trianglesRead += tn[i] - std::min(to[i], tn[i]);
    if (vo[i] == vn[i]) {
      e.trianglesKept += tn[i];
    } else {
      e.trianglesReformed += tn[i];
      ++e.objectsChanged;
    }
  }
  e.bytesRead = e.verticesRead * vb + e.trianglesRead * 12;
  return e;
}

// Orbit, fly-through and random jumps: large changes between frames.
std::vector<Camera> testPath(const Aabbd& bounds, Random& random) {
  std::vector<Camera> path = orbitPath(bounds, {.frames = 12});
  for (const Camera& c : flyThroughPath(bounds, {.frames = 12})) path.push_back(c);
  for (int k = 0; k < 12; ++k) {
    const Vec3d size = bounds.size();
    Camera c = Camera::lookAt(
        bounds.center() + Vec3d{random.uniform(-1, 1) * size.x, random.uniform(-1, 1) * size.y,
                                random.uniform(-1, 1) * size.z},
        bounds.center(), {0, 0, 1}, 60, 800, 600);
    fitClipPlanes(c, bounds);
    path.push_back(c);
  }
  return path;
}

// A copy of the arrays that takes only what each update wrote, as the renderer's GPU buffers do:
// after every frame each object's slot must read the same in the copy as in the buffer.
struct Mirror {
  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<std::uint32_t> source, indices;
  std::uint64_t held = 0;  // the update the copy holds
  std::uint64_t bytes = 0, wholeBytes = 0;

  template <class T>
  static std::uint64_t take(std::vector<T>& into, std::span<const T> from, std::uint64_t width,
                            std::span<const StreamBuffer::Range> ranges) {
    if (from.empty()) return 0;  // the package lacks the attribute
    if (into.size() < from.size()) into.resize(from.size());
    std::uint64_t bytes = 0;
    for (const StreamBuffer::Range& r : ranges) {
      std::copy(from.begin() + width * r.begin, from.begin() + width * r.end,
                into.begin() + width * r.begin);
      bytes += (r.end - r.begin) * width * sizeof(T);
    }
    return bytes;
  }

  void follow(const StreamBuffer& b, std::size_t maxRanges, const std::string& where) {
    ASSERT_EQ(b.previousUpdate(), held) << where;
    std::vector<StreamBuffer::Range> v, t;
    b.writtenRanges(maxRanges, v, t);
    ASSERT_LE(v.size(), maxRanges) << where;
    ASSERT_LE(t.size(), maxRanges) << where;
    for (std::size_t k = 1; k < v.size(); ++k) ASSERT_GT(v[k].begin, v[k - 1].end) << where;
    for (std::size_t k = 1; k < t.size(); ++k) ASSERT_GT(t[k].begin, t[k - 1].end) << where;
    bytes += take(positions, b.positions(), 1, v) + take(normals, b.normals(), 1, v) +
             take(colors, b.colors(), 1, v) + take(source, b.sourceTriangles(), 3, t) +
             take(indices, b.indices(), 3, t);
    wholeBytes += b.positions().size_bytes() + b.normals().size_bytes() + b.colors().size_bytes() +
                  b.sourceTriangles().size_bytes() + b.indices().size_bytes();
    held = b.lastUpdate();
  }

  template <class T>
  static bool sameSlot(const std::vector<T>& copy, std::span<const T> array, std::uint64_t begin,
                       std::uint64_t end) {
    return array.empty() ||
           std::equal(array.begin() + begin, array.begin() + end, copy.begin() + begin);
  }

  void expectSameSlots(const StreamBuffer& b, const std::string& where) const {
    for (std::size_t i = 0; i < b.vertexCounts().size(); ++i) {
      const std::uint64_t v = b.vertexStart()[i], vEnd = v + b.vertexCounts()[i];
      const std::uint64_t t = 3 * b.triangleStart()[i], tEnd = t + 3 * b.triangleCounts()[i];
      ASSERT_TRUE(sameSlot(positions, b.positions(), v, vEnd)) << where << " object " << i;
      ASSERT_TRUE(sameSlot(normals, b.normals(), v, vEnd)) << where << " object " << i;
      ASSERT_TRUE(sameSlot(colors, b.colors(), v, vEnd)) << where << " object " << i;
      ASSERT_TRUE(sameSlot(source, b.sourceTriangles(), t, tEnd)) << where << " object " << i;
      ASSERT_TRUE(sameSlot(indices, b.indices(), t, tEnd)) << where << " object " << i;
    }
  }
};

struct PathTally {
  std::uint64_t reformed = 0, kept = 0, relocated = 0, compactions = 0;
  std::uint64_t copiedBytes = 0, wholeBytes = 0;  // by the mirror, and had it taken all
};

// One package along the test path with a budget drifting up to `maxShare` of the full model, in
// a buffer whose capacity is `capacityShare` of it: every frame checked.
PathTally runPath(const char* key, double capacityShare, double maxShare, Random& random) {
  const Package& package = test::RuntimePackages::get(key);
  const LodScene scene = LodScene::fromPackage(package);
  const std::uint64_t full = scene.totalMaxVertices();
  StreamBuffer buffer(package, StreamCapacity::forVertices(
                                   package, static_cast<std::uint64_t>(capacityShare * full)));
  const std::vector<Camera> path = testPath(test::packageBounds(package), random);
  Selection s;
  std::vector<std::uint32_t> lastV(scene.size(), 0), lastT(scene.size(), 0);
  PathTally tally;
  Mirror mirror;
  // From 1 to 64 ranges a frame, drawn apart from the path's own random numbers.
  Random rangeCounts = Random::forItem(7, std::string_view(key).size());
  for (std::size_t f = 0; f < path.size(); ++f) {
    // The budget drifts too, as a user drags the slider.
    const auto budget = static_cast<std::uint64_t>(double(full) * random.uniform(0.02, maxShare));
    selectTwoPass(scene, path[f], budget, {}, s);
    EXPECT_EQ(s.totalVertices, std::min(budget, full));
    const Slots before(buffer);
    Result<FrameStats> stats = buffer.update(s.vertexCounts, s.triangleCounts);
    EXPECT_TRUE(stats.ok()) << stats.error().message;
    if (!stats.ok()) return tally;
    const std::string where = std::string(key) + " frame " + std::to_string(f);
    // Slots checked every third frame, so objects relocate more than once between two looks.
    expectEqualsReference(buffer, package, s, where, f % 3 == 2 || f + 1 == path.size());
    expectMoves(package, before, buffer, lastV, lastT, *stats, where);
    mirror.follow(buffer, 1 + rangeCounts.below(64), where);
    mirror.expectSameSlots(buffer, where);
    const FrameStats e = expectedStats(package, lastV, lastT, s.vertexCounts, s.triangleCounts);
    EXPECT_EQ(stats->bytesRead, e.bytesRead) << where;
    EXPECT_EQ(stats->verticesRead, e.verticesRead) << where;
    EXPECT_EQ(stats->trianglesRead, e.trianglesRead) << where;
    EXPECT_EQ(stats->trianglesReformed, e.trianglesReformed) << where;
    EXPECT_EQ(stats->trianglesKept, e.trianglesKept) << where;
    EXPECT_EQ(stats->objectsChanged, e.objectsChanged) << where;
    EXPECT_LE(stats->objectsRelocated, stats->objectsChanged) << where;
    EXPECT_EQ(stats->trianglesReformed + stats->trianglesKept, s.totalTriangles) << where;
    tally.reformed += stats->trianglesReformed;
    tally.kept += stats->trianglesKept;
    tally.relocated += stats->objectsRelocated;
    tally.compactions += stats->compacted ? 1 : 0;
    lastV = s.vertexCounts;
    lastT = s.triangleCounts;
  }
  tally.copiedBytes = mirror.bytes;
  tally.wholeBytes = mirror.wholeBytes;
  return tally;
}

TEST(Stream, EveryFrameEqualsAFreshBuildAlongRandomPaths) {
  Random random(21);
  for (const char* key : {"engine", "motor", "horse", "cad"}) {
    const PathTally tally = runPath(key, 1.0, 0.6, random);
    // Both index paths ran.
    EXPECT_GT(tally.reformed, 0u) << key;
    if (std::string(key) != "horse") {
      EXPECT_GT(tally.kept, 0u) << key;
    }
    EXPECT_GT(tally.relocated, 0u) << key;
    // What the frames wrote is less than the arrays they span.
    EXPECT_LT(tally.copiedBytes, tally.wholeBytes) << key;
  }
}

TEST(Stream, AFullArenaCompactsAndEveryFrameStillEqualsAFreshBuild) {
  // Selections near the capacity fill the arena (twice the capacity) with moved slots.
  Random random(22);
  std::uint64_t compactions = 0;
  for (const char* key : {"engine", "motor", "cad"}) {
    const PathTally tally = runPath(key, 0.5, 0.5, random);
    compactions += tally.compactions;
  }
  EXPECT_GT(compactions, 0u);
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
  EXPECT_EQ(again->bytesMoved, 0u);
  EXPECT_EQ(again->trianglesReformed, 0u);
  EXPECT_EQ(again->trianglesKept, s.totalTriangles);
  expectEqualsReference(buffer, package, s, "unchanged");
  std::vector<StreamBuffer::Range> vertices, triangles;
  buffer.writtenRanges(StreamBuffer::kUploadRanges, vertices, triangles);
  EXPECT_TRUE(vertices.empty() && triangles.empty()) << "an unchanged frame writes nothing";
  buffer.clear();
  Result<FrameStats> fresh = buffer.update(s.vertexCounts, s.triangleCounts);
  ASSERT_TRUE(fresh.ok());
  EXPECT_EQ(fresh->bytesRead, first->bytesRead);
  EXPECT_EQ(fresh->trianglesReformed, s.totalTriangles);
  expectEqualsReference(buffer, package, s, "after clear");
  // After clear every object's slot was written again.
  buffer.writtenRanges(StreamBuffer::kUploadRanges, vertices, triangles);
  const auto inside = [](const std::vector<StreamBuffer::Range>& ranges, std::uint64_t begin,
                         std::uint64_t end) {
    return std::any_of(ranges.begin(), ranges.end(),
                       [&](const auto& r) { return r.begin <= begin && end <= r.end; });
  };
  for (std::size_t i = 0; i < s.vertexCounts.size(); ++i) {
    if (s.vertexCounts[i] == 0) continue;
    const std::uint64_t v = buffer.vertexStart()[i], t = buffer.triangleStart()[i];
    EXPECT_TRUE(inside(vertices, v, v + s.vertexCounts[i])) << "object " << i;
    if (s.triangleCounts[i]) {
      EXPECT_TRUE(inside(triangles, t, t + s.triangleCounts[i])) << "object " << i;
    }
  }
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
  const std::uint64_t last = buffer.lastUpdate(), previous = buffer.previousUpdate();
  Result<FrameStats> refused = buffer.update(big.vertexCounts, big.triangleCounts);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(buffer.lastUpdate(), last);  // nothing written: a copy stays valid
  EXPECT_EQ(buffer.previousUpdate(), previous);
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
