#include "lodforge/simplify/progressive.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include "lodforge/core/mesh.h"
#include "lodforge/core/random.h"
#include "lodforge/generate/cad.h"
#include "lodforge/io/mesh/gltf_reader.h"
#include "lodforge/io/model_io.h"
#include "lodforge/simplify/prepare.h"
#include "lodforge/simplify/reform.h"
#include "test_support.h"

namespace lodforge {
namespace {

using Triangle = std::array<std::uint32_t, 3>;

// The reference: start from the full rearranged mesh and apply the recorded collapses one by
// one (vertex p-1 first: every corner k becomes ecol[k], triangles with a repeated corner
// vanish), comparing with Algorithm 2 at the requested vertex counts. Independent of the build
// and of the reformation kernel: it walks forward with incidence lists.
struct ExactnessReport {
  std::size_t levelsChecked = 0;
};

// An order-free fingerprint of a multiset of triangles (corners in their order): the count and
// the sums of two 64-bit hashes of each triangle, from its corners taken in two different
// orders, kept as triangles come and go, so each level is compared without sorting both sides.
struct TriangleMultiset {
  std::uint64_t count = 0, first = 0, second = 0;
  static std::uint64_t mix(std::uint64_t x) {  // splitmix64's finaliser
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
  }
  void add(const Triangle& t, std::uint64_t sign) {
    count += sign;
    first += sign * mix(mix((std::uint64_t{t[0]} << 32) | t[1]) ^ t[2]);
    second += sign * mix(mix((std::uint64_t{t[2]} << 32) | t[0]) ^ (t[1] + 0x9e3779b97f4a7c15ull));
  }
  bool operator==(const TriangleMultiset&) const = default;
};
constexpr std::uint64_t kAdd = 1, kRemove = ~std::uint64_t{0};  // +1 and −1 modulo 2^64

ExactnessReport expectExact(const ProgressiveMesh& mesh, const std::vector<std::uint32_t>& levels,
                            const std::string& what) {
  ExactnessReport report;
  const std::uint32_t p = mesh.vertexCount(), q = mesh.q;
  const std::uint32_t T = mesh.triangleCount();
  std::vector<Triangle> current(T);
  std::vector<bool> alive(T, true);
  std::vector<std::vector<std::uint32_t>> incident(p);
  for (std::uint32_t t = 0; t < T; ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      current[t][k] = mesh.triangles[3 * t + k];
      incident[current[t][k]].push_back(t);
    }
  }
  TriangleMultiset expected;
  for (const Triangle& t : current) expected.add(t, kAdd);
  std::set<std::uint32_t> wanted(levels.begin(), levels.end());
  std::vector<std::uint32_t> reformed;
  for (std::uint32_t n = p;; --n) {
    if (wanted.count(n)) {
      ++report.levelsChecked;
      // map(n) is the surviving count, and the first map(n) re-formed triangles are exactly the
      // surviving ones (as a multiset), none degenerate.
      const std::uint32_t count = mesh.trianglesAt(n);
      EXPECT_EQ(count, expected.count) << what << " n=" << n;
      reformed.resize(3 * std::size_t{count});
      reformObject(std::span(mesh.triangles).first(3 * std::size_t{count}), mesh.ecol, n, 0,
                   reformed);
      TriangleMultiset actual;
      bool degenerate = false, outOfRange = false;
      for (std::size_t t = 0; t < count; ++t) {
        const Triangle tri{reformed[3 * t], reformed[3 * t + 1], reformed[3 * t + 2]};
        degenerate = degenerate || tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2];
        outOfRange = outOfRange || std::max({tri[0], tri[1], tri[2]}) >= n;
        actual.add(tri, kAdd);
      }
      EXPECT_FALSE(degenerate) << what << " degenerate triangle at n=" << n;
      EXPECT_FALSE(outOfRange) << what << " corner beyond n=" << n;
      EXPECT_TRUE(actual == expected) << what << ": other triangles at n=" << n;
      if (::testing::Test::HasFailure()) return report;
    }
    if (n == q) break;
    // Collapse vertex n-1 into its ECol target.
    const std::uint32_t from = n - 1, to = mesh.ecol[from];
    EXPECT_LT(to, from) << what << ": ECol chains must strictly decrease";
    for (std::uint32_t t : incident[from]) {
      if (!alive[t]) continue;
      expected.add(current[t], kRemove);
      for (std::uint32_t& c : current[t]) {
        if (c == from) c = to;
      }
      if (current[t][0] == current[t][1] || current[t][1] == current[t][2] ||
          current[t][0] == current[t][2]) {
        alive[t] = false;
      } else {
        expected.add(current[t], kAdd);
        incident[to].push_back(t);
      }
    }
  }
  return report;
}

// Every level for small meshes, a dense spread plus both ends for big ones.
std::vector<std::uint32_t> levelsOf(const ProgressiveMesh& mesh, std::uint32_t dense = 400) {
  std::vector<std::uint32_t> levels;
  const std::uint32_t p = mesh.vertexCount(), q = mesh.q;
  if (p - q <= dense) {
    for (std::uint32_t n = q; n <= p; ++n) levels.push_back(n);
    return levels;
  }
  for (std::uint32_t i = 0; i <= dense; ++i)
    levels.push_back(q + static_cast<std::uint32_t>(std::uint64_t{p - q} * i / dense));
  for (std::uint32_t n : {q, q + 1, p - 1, p}) levels.push_back(n);
  return levels;
}

ProgressiveMesh buildPrepared(std::span<const Vec3f> positions,
                              std::span<const std::uint32_t> indices,
                              const ProgressiveOptions& options = {}) {
  const PreparedObject prepared = prepareObject(positions, {}, {}, indices);
  return buildProgressive(prepared.positions, prepared.indices, prepared.normals, prepared.colors,
                          options);
}

// A bumpy grid with random holes: boundaries inside and out, varied curvature.
void randomSurface(std::uint64_t seed, std::vector<Vec3f>& positions,
                   std::vector<std::uint32_t>& indices) {
  Random random(seed);
  const int w = 6 + static_cast<int>(random.below(20)), h = 6 + static_cast<int>(random.below(20));
  positions.clear();
  indices.clear();
  for (int y = 0; y <= h; ++y) {
    for (int x = 0; x <= w; ++x)
      positions.push_back({float(x), float(y), float(random.uniform(-0.4, 0.4))});
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (random.uniform() < 0.06) continue;  // a hole
      const auto a = std::uint32_t(y * (w + 1) + x), b = a + 1, c = a + std::uint32_t(w) + 2,
                 d = a + std::uint32_t(w) + 1;
      indices.insert(indices.end(), {a, b, c, a, c, d});
    }
  }
}

TEST(Progressive, ExactOnRandomSurfacesAtEveryLevel) {
  for (std::uint64_t seed = 1; seed <= 25; ++seed) {
    std::vector<Vec3f> positions;
    std::vector<std::uint32_t> indices;
    randomSurface(seed, positions, indices);
    for (CollapseCost cost : {CollapseCost::kQuadric, CollapseCost::kMelax}) {
      for (CollapseDirection direction : {CollapseDirection::kCheaper, CollapseDirection::kPaper}) {
        const ProgressiveMesh mesh = buildPrepared(positions, indices, {cost, direction});
        EXPECT_LT(mesh.q, mesh.vertexCount());
        expectExact(mesh, levelsOf(mesh, 100000), fmt::format("seed {}", seed));
        if (HasFailure()) return;
      }
    }
  }
}

// The reference check can fail: a mesh whose first and last triangles trade places re-forms
// the wrong triangles at the counts where only one of them survives: the same number of them, so
// the count check passes, and the multisets (one re-formed triangle is degenerate) tell.
TEST(Progressive, TheExactnessCheckCatchesWrongTrianglesAtARightCount) {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  randomSurface(3, positions, indices);
  ProgressiveMesh mesh = buildPrepared(positions, indices);
  const std::size_t last = mesh.triangles.size() - 3;
  ASSERT_LT(mesh.trianglesAt(mesh.q), mesh.triangleCount());
  for (std::size_t k = 0; k < 3; ++k) std::swap(mesh.triangles[k], mesh.triangles[last + k]);
  ::testing::TestPartResultArray failures;
  {
    const ::testing::ScopedFakeTestPartResultReporter intercept(
        ::testing::ScopedFakeTestPartResultReporter::INTERCEPT_ONLY_CURRENT_THREAD, &failures);
    expectExact(mesh, levelsOf(mesh, 100000), "swapped");
  }
  bool multisets = false, counts = false;
  for (int i = 0; i < failures.size(); ++i) {
    const std::string message = failures.GetTestPartResult(i).message();
    counts = counts || message.find("swapped n=") != std::string::npos;
    multisets = multisets || message.find("swapped: other triangles at n=") != std::string::npos;
  }
  EXPECT_FALSE(counts) << "the swap changed a count";
  EXPECT_TRUE(multisets) << failures.size() << " failures, none of the multisets";
  // The fingerprint itself: blind to the triangles' order, not to their corners' or their count.
  const auto of = [](std::initializer_list<Triangle> triangles) {
    TriangleMultiset set;
    for (const Triangle& t : triangles) set.add(t, kAdd);
    return set;
  };
  EXPECT_TRUE(of({{1, 2, 3}, {4, 5, 6}}) == of({{4, 5, 6}, {1, 2, 3}}));
  EXPECT_FALSE(of({{1, 2, 3}, {4, 5, 6}}) == of({{1, 2, 3}, {4, 6, 5}}));
  EXPECT_FALSE(of({{1, 2, 3}, {1, 2, 3}}) == of({{1, 2, 3}, {4, 5, 6}}));
  TriangleMultiset back = of({{1, 2, 3}, {4, 5, 6}});
  back.add({4, 5, 6}, kRemove);
  EXPECT_TRUE(back == of({{1, 2, 3}}));
}

TEST(Progressive, RealMeshesAreExact) {
  for (const char* file : {"meshes/stanford-bunny.obj", "meshes/horse.ply"}) {
    Result<Model> model = readModel(test::dataPath(file));
    ASSERT_TRUE(model.ok());
    const ProgressiveMesh mesh = buildPrepared(model->positions, model->indices);
    const ExactnessReport report = expectExact(mesh, levelsOf(mesh), file);
    EXPECT_GE(report.levelsChecked, 400u);
    // Closed or nearly closed scans simplify to a tiny fraction.
    EXPECT_LT(mesh.trianglesAt(mesh.q), mesh.triangleCount() / 50) << file;
  }
}

TEST(Progressive, RealCadPartsAreExactAtEveryLevel) {
  std::size_t objects = 0;
  for (const char* file :
       {"meshes/2CylinderEngine.glb", "meshes/as1_motor.glb", "meshes/Motor-c.glb"}) {
    Result<Model> model = readModel(test::dataPath(file));
    ASSERT_TRUE(model.ok());
    for (std::size_t o = 0; o < model->objectCount(); ++o) {
      const ProgressiveMesh mesh =
          buildPrepared(model->objectPositions(o), model->objectIndices(o));
      expectExact(mesh, levelsOf(mesh), fmt::format("{} object {}", file, o));
      if (HasFailure()) return;
      ++objects;
    }
  }
  EXPECT_EQ(objects, 67u + 35u + 17u);
}

TEST(Progressive, GeneratedCadPartsAreExactAtEveryLevel) {
  test::TempDir dir;
  ASSERT_TRUE(generateCad({.objects = 120, .seed = 11}, dir.file("parts.glb")).ok());
  Result<Model> model = readGltf(dir.file("parts.glb"));
  ASSERT_TRUE(model.ok());
  for (std::size_t o = 0; o < model->objectCount(); ++o) {
    const ProgressiveMesh mesh = buildPrepared(model->objectPositions(o), model->objectIndices(o));
    expectExact(mesh, levelsOf(mesh), std::string(model->objectName(o)));
    if (HasFailure()) return;
  }
}

TEST(Progressive, BoundaryVerticesNeverMoveAndBoundaryEdgesSurvive) {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  randomSurface(77, positions, indices);
  const PreparedObject prepared = prepareObject(positions, {}, {}, indices);
  const ProgressiveMesh mesh = buildProgressive(prepared.positions, prepared.indices, {}, {});
  // Boundary edges of the input (one triangle), in rearranged numbering.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> count;
  for (std::size_t t = 0; t < prepared.indices.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = mesh.permuteV[prepared.indices[t + k]],
                          b = mesh.permuteV[prepared.indices[t + (k + 1) % 3]];
      count[{std::min(a, b), std::max(a, b)}]++;
    }
  }
  std::set<std::pair<std::uint32_t, std::uint32_t>> boundary;
  for (const auto& [edge, n] : count) {
    if (n == 1) boundary.insert(edge);
  }
  ASSERT_FALSE(boundary.empty());
  for (const auto& [a, b] : boundary) {
    EXPECT_LT(a, mesh.q);  // boundary vertices are among the q that never collapse
    EXPECT_LT(b, mesh.q);
  }
  // At the simplest level every input boundary edge is still an edge of the mesh.
  const std::uint32_t n = mesh.q;
  std::vector<std::uint32_t> reformed(3 * std::size_t{mesh.trianglesAt(n)});
  reformObject(std::span(mesh.triangles).first(reformed.size()), mesh.ecol, n, 0, reformed);
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (std::size_t t = 0; t < reformed.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = reformed[t + k], b = reformed[t + (k + 1) % 3];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  for (const auto& edge : boundary) EXPECT_TRUE(edges.count(edge));
}

TEST(Progressive, NoTriangleEverFlipsOnAPlane) {
  // A flat, irregular grid: every level must keep every triangle facing +z.
  Random random(3);
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  const int w = 30;
  for (int y = 0; y <= w; ++y) {
    for (int x = 0; x <= w; ++x) {
      const bool edge = x == 0 || y == 0 || x == w || y == w;
      positions.push_back({float(x) + (edge ? 0.0f : float(random.uniform(-0.3, 0.3))),
                           float(y) + (edge ? 0.0f : float(random.uniform(-0.3, 0.3))), 0});
    }
  }
  for (int y = 0; y < w; ++y) {
    for (int x = 0; x < w; ++x) {
      const auto a = std::uint32_t(y * (w + 1) + x), b = a + 1, c = a + w + 2, d = a + w + 1;
      indices.insert(indices.end(), {a, b, c, a, c, d});
    }
  }
  for (CollapseCost cost : {CollapseCost::kQuadric, CollapseCost::kMelax}) {
    const ProgressiveMesh mesh =
        buildPrepared(positions, indices, {cost, CollapseDirection::kCheaper});
    // The interior of a plane collapses almost completely: the last interior vertex may stay,
    // since collapsing it into a boundary vertex would leave zero-area triangles along a side.
    EXPECT_GE(mesh.q, std::uint32_t(4 * w));
    EXPECT_LE(mesh.q, std::uint32_t(4 * w + 2));
    EXPECT_LT(mesh.errorAt(mesh.q), 1e-9f);  // flat: no error at any level (up to rounding)
    for (std::uint32_t n = mesh.q; n <= mesh.vertexCount(); ++n) {
      std::vector<std::uint32_t> reformed(3 * std::size_t{mesh.trianglesAt(n)});
      reformObject(std::span(mesh.triangles).first(reformed.size()), mesh.ecol, n, 0, reformed);
      for (std::size_t t = 0; t < reformed.size(); t += 3) {
        const Vec3f a = mesh.positions[reformed[t]], b = mesh.positions[reformed[t + 1]],
                    c = mesh.positions[reformed[t + 2]];
        ASSERT_GT(cross(b - a, c - a).z, 0.0f) << "n=" << n;
      }
    }
  }
}

TEST(Progressive, ClosedSurfacesStayManifoldDownToTheirMinimum) {
  Result<Model> model = readModel(test::dataPath("meshes/horse.ply"));
  ASSERT_TRUE(model.ok());
  const ProgressiveMesh mesh = buildPrepared(model->positions, model->indices);
  for (std::uint32_t n : levelsOf(mesh, 40)) {
    std::vector<std::uint32_t> reformed(3 * std::size_t{mesh.trianglesAt(n)});
    reformObject(std::span(mesh.triangles).first(reformed.size()), mesh.ecol, n, 0, reformed);
    EXPECT_EQ(countBoundaryEdges(reformed), 0u)
        << "n=" << n;  // the horse is closed: it stays closed
    // No undirected edge used by three triangles or more: sorted, no key three times in a row.
    std::vector<std::uint64_t> edges;
    for (std::size_t t = 0; t < reformed.size(); t += 3) {
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint64_t a = reformed[t + k], b = reformed[t + (k + 1) % 3];
        edges.push_back(std::min(a, b) << 32 | std::max(a, b));
      }
    }
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 2; i < edges.size(); ++i)
      ASSERT_FALSE(edges[i] == edges[i - 2]) << "non-manifold edge at n=" << n;
  }
  EXPECT_LE(mesh.q, 8u);  // a closed genus-0 surface ends near a tetrahedron
}

TEST(Progressive, ErrorTableIsMonotoneAndGrowsAsDetailGoes) {
  Result<Model> model = readModel(test::dataPath("meshes/stanford-bunny.obj"));
  ASSERT_TRUE(model.ok());
  const ProgressiveMesh mesh = buildPrepared(model->positions, model->indices);
  ASSERT_EQ(mesh.error.size(), mesh.vertexCount() - mesh.q + 1);
  EXPECT_EQ(mesh.error.back(), 0.0f);
  for (std::size_t i = 1; i < mesh.error.size(); ++i) ASSERT_LE(mesh.error[i], mesh.error[i - 1]);
  EXPECT_GT(mesh.error.front(), 0.0f);
  // vertexCountForError inverts the table.
  const float e = mesh.errorAt((mesh.q + mesh.vertexCount()) / 2);
  const std::uint32_t n = mesh.vertexCountForError(e);
  EXPECT_LE(mesh.errorAt(n), e);
  EXPECT_TRUE(n == mesh.q || mesh.errorAt(n - 1) > e);
}

// The shared lookup over a non-increasing table is the first entry that fits, as a scan finds
// it: random tables with runs of equal errors, queries on, between and beyond their entries.
TEST(Progressive, VertexCountForErrorIsTheFirstEntryThatFits) {
  Random random(17);
  for (int round = 0; round < 500; ++round) {
    std::vector<float> table(1 + random.below(40));
    float e = static_cast<float>(random.uniform(0, 10));
    for (float& entry : table) {
      entry = e;
      if (random.below(3) != 0) e = static_cast<float>(e * random.uniform(0.2, 1.0));
    }
    const auto fewest = static_cast<std::uint32_t>(random.below(100));
    for (double allowed : {static_cast<double>(table[random.below(table.size())]),
                           random.uniform(-1, 11), -1.0, 11.0}) {
      const auto scan =
          std::find_if(table.begin(), table.end(), [&](float entry) { return entry <= allowed; });
      EXPECT_EQ(vertexCountForError(table, fewest, allowed),
                fewest + static_cast<std::uint32_t>(scan - table.begin()))
          << "round " << round << ", allowed " << allowed;
    }
  }
}

// maxError refuses the collapses past it: the result's error stays within the bound, and the
// bound is what stops it (a larger one collapses further).
TEST(SimplifyMesh, MaxErrorHoldsTheVertexErrorWithinIt) {
  Result<Model> model = readModel(test::dataPath("meshes/stanford-bunny.obj"));
  ASSERT_TRUE(model.ok());
  const PreparedObject bunny =
      prepareObject(model->positions, {}, {}, model->indices, {.normals = false});
  const std::size_t triangles = bunny.indices.size() / 3;
  std::size_t previous = triangles;
  for (const double bound : {1e-4, 1e-3, 4e-3}) {
    ProgressiveOptions options;
    options.maxError = bound;
    const SimplifiedMesh mesh = simplifyMesh(bunny.positions, bunny.indices, options);
    EXPECT_LE(mesh.error, bound * (1 + 1e-6));  // the error is kept as a float
    EXPECT_GT(mesh.error, 0.25 * bound);        // it went close to the bound
    EXPECT_LT(mesh.indices.size() / 3, previous) << bound;
    previous = mesh.indices.size() / 3;
  }
  EXPECT_GT(previous, 100u);  // not to the minimum
}

TEST(SimplifyMesh, StopsAtTheTargetKeepsLockedVerticesAndHonoursTheNormalLimit) {
  Result<Model> model = readModel(test::dataPath("meshes/stanford-bunny.obj"));
  ASSERT_TRUE(model.ok());
  const PreparedObject bunny =
      prepareObject(model->positions, {}, {}, model->indices, {.normals = false});
  const std::uint32_t triangles = static_cast<std::uint32_t>(bunny.indices.size() / 3);

  ProgressiveOptions options;
  options.stopAtTriangles = triangles / 10;
  const SimplifiedMesh tenth = simplifyMesh(bunny.positions, bunny.indices, options);
  EXPECT_LE(tenth.indices.size() / 3, options.stopAtTriangles);
  EXPECT_GE(tenth.indices.size() / 3, options.stopAtTriangles - 2);  // one collapse removes <= 2
  EXPECT_GT(tenth.error, 0.0f);
  // The same mesh as the progressive build's level with that many triangles.
  const ProgressiveMesh full = buildProgressive(bunny.positions, bunny.indices, {}, {});
  std::uint32_t n = full.q;
  while (full.trianglesAt(n) < tenth.indices.size() / 3) ++n;
  std::vector<std::uint32_t> level(3 * std::size_t{full.trianglesAt(n)});
  reformObject(std::span(full.triangles).first(level.size()), full.ecol, n, 0, level);
  std::multiset<std::array<Vec3f, 3>,
                bool (*)(const std::array<Vec3f, 3>&, const std::array<Vec3f, 3>&)>
      a([](const auto&x, const auto&y) {
        return std::lexicographical_compare(&x[0].x, &x[0].x + 9, &y[0].x, &y[0].x + 9);
      }),
      b(a.key_comp());
  for (std::size_t t = 0; t < level.size(); t += 3)
    a.insert(
        {full.positions[level[t]], full.positions[level[t + 1]], full.positions[level[t + 2]]});
  for (std::size_t t = 0; t < tenth.indices.size(); t += 3) {
    const auto at = [&](std::size_t k) {
      return bunny.positions[tenth.vertices[tenth.indices[t + k]]];
    };
    b.insert({at(0), at(1), at(2)});
  }
  EXPECT_TRUE(a == b);

  // Locked vertices stay.
  std::vector<std::uint8_t> locked(bunny.positions.size(), 0);
  for (std::size_t v = 0; v < locked.size(); v += 17) locked[v] = 1;
  options.locked = locked;
  const SimplifiedMesh pinned = simplifyMesh(bunny.positions, bunny.indices, options);
  std::vector<std::uint8_t> kept(bunny.positions.size(), 0);
  for (std::uint32_t v : pinned.vertices) kept[v] = 1;
  for (std::size_t v = 0; v < locked.size(); ++v) {
    if (locked[v]) {
      ASSERT_TRUE(kept[v]) << v;
    }
  }

  // A strict normal limit stops earlier than the default one, and no face turns past it.
  options.locked = {};
  options.stopAtTriangles = 1;
  options.minNormalCos = std::cos(10 * 3.14159265358979 / 180);
  const SimplifiedMesh strict = simplifyMesh(bunny.positions, bunny.indices, options);
  options.minNormalCos = 0.25;
  const SimplifiedMesh loose = simplifyMesh(bunny.positions, bunny.indices, options);
  EXPECT_GT(strict.indices.size(), 2 * loose.indices.size());
}

TEST(Progressive, AttributesFollowTheirVertices) {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices;
  randomSurface(5, positions, indices);
  std::vector<Rgba8> colors(positions.size());
  for (std::size_t v = 0; v < colors.size(); ++v)
    colors[v] = {std::uint8_t(v), std::uint8_t(v >> 8), 7, 255};
  std::vector<Vec3f> normals(positions.size(), Vec3f{0, 0, 1});
  const ProgressiveMesh mesh = buildProgressive(positions, indices, normals, colors);
  for (std::size_t v = 0; v < positions.size(); ++v) {
    EXPECT_EQ(mesh.positions[mesh.permuteV[v]], positions[v]);
    EXPECT_EQ(mesh.colors[mesh.permuteV[v]], colors[v]);
  }
  for (std::size_t t = 0; t < indices.size() / 3; ++t) {
    for (std::size_t k = 0; k < 3; ++k)
      EXPECT_EQ(mesh.triangles[3 * mesh.permuteT[t] + k], mesh.permuteV[indices[3 * t + k]]);
  }
}

// A flat square of n x n cells, textured: each vertex has one wedge per chart its cells belong
// to, charts given per cell, coordinates by a function of the chart and the point.
struct TexturedGrid {
  std::vector<Vec3f> positions;
  std::vector<std::uint32_t> indices, wedges;
  std::vector<Vec2f> uvs;
  std::vector<std::uint32_t> wedgeVertex, wedgeChart;
};

template <class Chart, class Uv>
TexturedGrid texturedGrid(int n, Chart chartOf, Uv uvOf) {
  TexturedGrid grid;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> wedgeOf;  // (vertex, chart)
  const auto vertex = [&](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      grid.positions.push_back({float(i) / float(n), float(j) / float(n), 0});
  const auto corner = [&](std::uint32_t v, std::uint32_t chart) {
    const auto [at, fresh] = wedgeOf.emplace(std::pair{v, chart}, grid.uvs.size());
    if (fresh) {
      grid.uvs.push_back(uvOf(chart, grid.positions[v]));
      grid.wedgeVertex.push_back(v);
      grid.wedgeChart.push_back(chart);
    }
    grid.indices.push_back(v);
    grid.wedges.push_back(at->second);
  };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const std::uint32_t chart = chartOf((i + 0.5) / n, (j + 0.5) / n);
      for (std::uint32_t v : {vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j),
                              vertex(i + 1, j + 1), vertex(i, j + 1)})
        corner(v, chart);
    }
  }
  return grid;
}

double uvArea(Vec2f a, Vec2f b, Vec2f c) {
  return (double(b.x) - a.x) * (double(c.y) - a.y) - (double(c.x) - a.x) * (double(b.y) - a.y);
}

// Three charts on an n x n grid of the unit square: the left half, and the right half cut in
// two (a T where the seams meet), each mapped the right way round.
TexturedGrid threeChartGrid(int n) {
  const auto chartOf = [](double x, double y) { return x < 0.5 ? 0u : y < 0.5 ? 1u : 2u; };
  const auto uvOf = [](std::uint32_t chart, Vec3f p) {
    return Vec2f{0.3f * p.x + 0.3f * float(chart), 0.5f * p.y};
  };
  return texturedGrid(n, chartOf, uvOf);
}

TEST(SimplifyMesh, TexturedSeamsSlideAlongThemselvesAndEveryTriangleKeepsOneChart) {
  const TexturedGrid grid = threeChartGrid(24);
  ProgressiveOptions options;
  options.wedges = grid.wedges;
  options.wedgeUvs = grid.uvs;
  options.stopAtTriangles = 1;
  const SimplifiedMesh out = simplifyMesh(grid.positions, grid.indices, options);
  ASSERT_EQ(out.wedges.size(), out.indices.size());
  ASSERT_GT(out.indices.size(), 0u);
  double area = 0;
  std::set<std::uint32_t> seamVertices;
  for (std::size_t t = 0; t < out.indices.size(); t += 3) {
    std::array<Vec3f, 3> p;
    std::array<Vec2f, 3> uv;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = out.vertices[out.indices[t + k]], w = out.wedges[t + k];
      // Each corner's wedge belongs to its vertex, and the triangle's wedges to one chart.
      ASSERT_EQ(grid.wedgeVertex[w], v) << "triangle " << t / 3;
      ASSERT_EQ(grid.wedgeChart[w], grid.wedgeChart[out.wedges[t]]) << "triangle " << t / 3;
      p[k] = grid.positions[v];
      uv[k] = grid.uvs[w];
    }
    // Never turned over in texture space (every chart is mapped the right way round).
    EXPECT_GT(uvArea(uv[0], uv[1], uv[2]), 0) << "triangle " << t / 3;
    area += 0.5 * length(cross(toDouble(p[1] - p[0]), toDouble(p[2] - p[0])));
  }
  // Still the whole square (the rim stays, nothing folds), in far fewer triangles.
  EXPECT_NEAR(area, 1.0, 1e-5);
  EXPECT_LT(out.indices.size() / 3, grid.indices.size() / 3 / 10);
  // The seams simplified along themselves: the vertices with two charts' wedges are on a seam,
  // and far fewer of them are left than the 25 + 12 the seams had.
  std::map<std::uint32_t, std::set<std::uint32_t>> chartsAt;
  for (std::size_t i = 0; i < out.wedges.size(); ++i)
    chartsAt[out.vertices[out.indices[i]]].insert(grid.wedgeChart[out.wedges[i]]);
  std::size_t onSeams = 0;
  for (const auto& [v, charts] : chartsAt) {
    if (charts.size() < 2) continue;
    const Vec3f p = grid.positions[v];
    EXPECT_TRUE(p.x == 0.5f || (p.y == 0.5f && p.x >= 0.5f)) << p.x << " " << p.y;
    ++onSeams;
  }
  EXPECT_GE(onSeams, 3u);  // both ends of the long seam and the T
  EXPECT_LT(onSeams, 12u);
}

TEST(ProgressiveMesh, TexturedLevelsKeepOneChartPerTriangleAndNoCrackAtEveryWholeCount) {
  const TexturedGrid grid = threeChartGrid(16);
  ProgressiveOptions options;
  options.wedges = grid.wedges;
  options.wedgeUvs = grid.uvs;
  const ProgressiveMesh mesh = buildProgressive(grid.positions, grid.indices, {}, {}, options);
  // Over the wedges: one vertex each, with its own coordinates.
  ASSERT_EQ(mesh.vertexCount(), grid.uvs.size());
  ASSERT_EQ(mesh.uvs.size(), grid.uvs.size());
  ASSERT_EQ(mesh.whole.size(), mesh.map.size());
  std::vector<std::uint32_t> wedgeOf(mesh.vertexCount());
  for (std::uint32_t w = 0; w < grid.uvs.size(); ++w) {
    wedgeOf[mesh.permuteV[w]] = w;
    EXPECT_EQ(mesh.uvs[mesh.permuteV[w]], grid.uvs[w]);
    EXPECT_EQ(mesh.positions[mesh.permuteV[w]], grid.positions[grid.wedgeVertex[w]]);
  }
  // Whether the triangles at n vertices draw some input point at two places (a crack): the
  // corners that were one point must all go to one place.
  const auto cracked = [&](std::uint32_t n, std::span<const std::uint32_t> reformed) {
    std::map<std::uint32_t, Vec3f> pointAt;
    for (std::size_t c = 0; c < reformed.size(); ++c) {
      const std::uint32_t inputPoint = grid.wedgeVertex[wedgeOf[mesh.triangles[c]]];
      const auto [at, fresh] = pointAt.emplace(inputPoint, mesh.positions[reformed[c]]);
      if (at->second != mesh.positions[reformed[c]]) return true;
    }
    return n == 0;  // (never: n >= q > 0)
  };
  std::size_t wholeCounts = 0, partialCounts = 0, crackedPartials = 0;
  for (std::uint32_t n = mesh.q; n <= mesh.vertexCount(); ++n) {
    const std::uint32_t triangles = mesh.trianglesAt(n);
    std::vector<std::uint32_t> reformed(3 * std::size_t{triangles});
    reformObject(std::span(mesh.triangles).first(reformed.size()), mesh.ecol, n, 0, reformed);
    if (mesh.wholeAt(n) != n) {
      // Not whole: some point is half collapsed, which is why such counts are never drawn.
      ++partialCounts;
      EXPECT_LT(mesh.wholeAt(n), n);
      EXPECT_EQ(mesh.wholeAt(mesh.wholeAt(n)), mesh.wholeAt(n));
      crackedPartials += cracked(n, reformed) ? 1u : 0u;
      continue;
    }
    ++wholeCounts;
    ASSERT_FALSE(cracked(n, reformed)) << "at " << n << " vertices";
    double area = 0;
    for (std::size_t t = 0; t < reformed.size(); t += 3) {
      std::array<Vec2f, 3> uv;
      for (std::size_t k = 0; k < 3; ++k) {
        ASSERT_LT(reformed[t + k], n);
        const std::uint32_t w = wedgeOf[reformed[t + k]];
        ASSERT_EQ(grid.wedgeChart[w], grid.wedgeChart[wedgeOf[reformed[t]]])
            << "triangle " << t / 3 << " at " << n << " vertices mixes two charts";
        uv[k] = mesh.uvs[reformed[t + k]];
      }
      EXPECT_GT(uvArea(uv[0], uv[1], uv[2]), 0) << "triangle " << t / 3 << " at " << n;
      const Vec3f a = mesh.positions[reformed[t]], b = mesh.positions[reformed[t + 1]],
                  c = mesh.positions[reformed[t + 2]];
      area += 0.5 * length(cross(toDouble(b - a), toDouble(c - a)));
    }
    // The whole square at every level: nothing folds, nothing opens.
    ASSERT_NEAR(area, 1.0, 1e-5) << "at " << n << " vertices";
  }
  // Seam points have several wedges, so some counts are not whole; the coarsest level is small
  // (the rim's 64 points stay: borders do not collapse by default).
  EXPECT_GT(partialCounts, 0u);
  EXPECT_GT(crackedPartials, 0u);
  EXPECT_GT(wholeCounts, mesh.vertexCount() / 2);
  EXPECT_LT(mesh.map.front(), grid.indices.size() / 3 / 6);
}

// The largest texture-coordinate error over the square of the simplified mesh, each of its
// triangles interpolating its corners' coordinates, against the exact coordinates `uvOf`.
template <class Uv>
double largestUvError(const TexturedGrid& grid, const SimplifiedMesh& out, Uv uvOf) {
  double worst = 0;
  for (int j = 0; j <= 60; ++j) {
    for (int i = 0; i <= 60; ++i) {
      const double x = i / 60.0, y = j / 60.0;
      for (std::size_t t = 0; t < out.indices.size(); t += 3) {
        const auto at = [&](std::size_t k) {
          return grid.positions[out.vertices[out.indices[t + k]]];
        };
        const Vec3f a = at(0), b = at(1), c = at(2);
        const double d =
            (double(b.x) - a.x) * (double(c.y) - a.y) - (double(c.x) - a.x) * (double(b.y) - a.y);
        const double s = ((x - a.x) * (double(c.y) - a.y) - (double(c.x) - a.x) * (y - a.y)) / d;
        const double r = ((double(b.x) - a.x) * (y - a.y) - (x - a.x) * (double(b.y) - a.y)) / d;
        if (s < -1e-9 || r < -1e-9 || s + r > 1 + 1e-9) continue;
        const Vec2f ta = uvOf(at(0)), tb = uvOf(at(1)), tc = uvOf(at(2));
        const Vec2f exact = uvOf(Vec3f{float(x), float(y), 0});
        const double u = ta.x + s * (tb.x - ta.x) + r * (tc.x - ta.x);
        const double v = ta.y + s * (tb.y - ta.y) + r * (tc.y - ta.y);
        worst = std::max(worst, std::hypot(u - exact.x, v - exact.y));
        break;
      }
    }
  }
  return worst;
}

TEST(SimplifyMesh, TextureErrorIsPartOfTheCost) {
  // A flat square whose texture is stretched in one place: geometry alone sees nothing to keep
  // there; with the texture in the cost, the simplified mesh follows the stretch.
  const auto stretched = [](Vec3f p) {
    const double bump = 0.06 * std::exp(-(std::pow(p.x - 0.3, 2) + std::pow(p.y - 0.6, 2)) / 0.01);
    return Vec2f{float(p.x + bump), p.y};
  };
  const auto one = [](double, double) { return 0u; };
  const TexturedGrid grid =
      texturedGrid(30, one, [&](std::uint32_t, Vec3f p) { return stretched(p); });
  // The same collapses blind to the texture: coordinates that are affine everywhere.
  const TexturedGrid blind = texturedGrid(30, one, [](std::uint32_t, Vec3f p) {
    return Vec2f{p.x, p.y};
  });
  ProgressiveOptions options;
  options.stopAtTriangles = static_cast<std::uint32_t>(grid.indices.size() / 3 / 12);
  options.wedges = grid.wedges;
  options.wedgeUvs = grid.uvs;
  const SimplifiedMesh aware = simplifyMesh(grid.positions, grid.indices, options);
  options.wedgeUvs = blind.uvs;
  const SimplifiedMesh unaware = simplifyMesh(grid.positions, grid.indices, options);
  EXPECT_LE(aware.indices.size(), 3 * std::size_t{options.stopAtTriangles});
  const double withTexture = largestUvError(grid, aware, stretched);
  const double without = largestUvError(grid, unaware, stretched);
  EXPECT_LT(withTexture, 0.5 * without) << withTexture << " against " << without;
}

}  // namespace
}  // namespace lodforge
