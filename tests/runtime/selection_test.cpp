#include "lodforge/runtime/selection.h"

#include <algorithm>
#include <cstdio>
#include <numeric>

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "lodforge/runtime/path.h"
#include "packages.h"

namespace lodforge {
namespace {

const char* const kPackages[] = {"engine", "motor", "horse", "cad", "crowd"};

// Cameras around and inside the model: an orbit, a fly-through and random views.
std::vector<Camera> camerasFor(const Package& package, Random& random, std::size_t randomViews) {
  const Aabbd bounds = test::packageBounds(package);
  std::vector<Camera> cameras = orbitPath(bounds, {.frames = 6, .width = 800, .height = 600});
  for (const Camera& c : flyThroughPath(bounds, {.frames = 6, .width = 640, .height = 480}))
    cameras.push_back(c);
  const Vec3d size = bounds.size();
  for (std::size_t k = 0; k < randomViews; ++k) {
    const auto inBox = [&](double grow) {
      return bounds.center() + Vec3d{random.uniform(-grow, grow) * size.x,
                                     random.uniform(-grow, grow) * size.y,
                                     random.uniform(-grow, grow) * size.z};
    };
    Camera c = Camera::lookAt(inBox(1.5), inBox(0.5), {0, 0, 1}, random.uniform(30, 90), 1024, 768);
    fitClipPlanes(c, bounds);
    cameras.push_back(c);
  }
  return cameras;
}

// Algorithm 3 and the partial allocation restated as one greedy walk, the test's oracle: upward,
// objects by importance (descending, ties by id) take what they lack while the gap lasts, an
// object at zero only if the rest covers its minimum; downward, objects by importance
// (ascending, ties by id) drop to zero until the excess is covered, and the overshoot goes back
// to the most important first. Returns what could not be placed.
std::uint64_t oracle(const LodScene& scene, const std::vector<float>& importance,
                     std::uint64_t budget, std::vector<std::uint32_t>& vc) {
  const std::uint64_t current = std::accumulate(vc.begin(), vc.end(), std::uint64_t{0});
  const std::uint64_t target = std::min(budget, scene.totalMaxVertices());
  std::vector<std::uint32_t> order;
  for (std::uint32_t i = 0; i < vc.size(); ++i) {
    if (importance[i] > 0) order.push_back(i);
  }
  const auto give = [&](const std::vector<std::uint32_t>& byImportance, std::uint64_t left) {
    for (std::uint32_t i : byImportance) {
      const std::uint32_t lo = scene.minVertices[i], hi = scene.maxVertices[i];
      if (left == 0) break;
      if (vc[i] >= hi || (vc[i] == 0 && left < lo)) continue;
      const std::uint64_t add = std::min<std::uint64_t>(left, hi - vc[i]);
      vc[i] += static_cast<std::uint32_t>(add);
      left -= add;
    }
    return left;
  };
  if (current <= target) {
    std::stable_sort(order.begin(), order.end(),
                     [&](auto a, auto b) { return importance[a] > importance[b]; });
    for (std::uint32_t i = 0; i < vc.size(); ++i) {
      if (!(importance[i] > 0)) order.push_back(i);  // hidden objects last
    }
    return give(order, target - current);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](auto a, auto b) { return importance[a] < importance[b]; });
  std::uint64_t dropped = 0;
  for (std::uint32_t i : order) {
    if (dropped >= current - target) break;
    dropped += std::exchange(vc[i], 0u);
  }
  std::reverse(order.begin(), order.end());
  return give(order, dropped - (current - target));
}

void expectValidCounts(const LodScene& scene, const Package& package, const Selection& s) {
  std::uint64_t vertices = 0, triangles = 0;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    const std::uint32_t v = s.vertexCounts[i];
    ASSERT_TRUE(v == 0 || (v >= scene.minVertices[i] && v <= scene.maxVertices[i]))
        << i << ": " << v;
    ASSERT_EQ(s.triangleCounts[i], v == 0 ? 0u : package.trianglesAt(i, v)) << i;
    vertices += v;
    triangles += s.triangleCounts[i];
  }
  EXPECT_EQ(vertices, s.totalVertices);
  EXPECT_EQ(triangles, s.totalTriangles);
}

TEST(Selection, SumsToExactlyTheBudgetOnRealPackagesFromAnyView) {
  Random random(11);
  std::uint64_t exact = 0, checked = 0, unreachable = 0, shortOfBudget = 0;
  for (const char* key : kPackages) {
    const Package& package = test::RuntimePackages::get(key);
    const LodScene scene = LodScene::fromPackage(package);
    const std::uint64_t full = scene.totalMaxVertices();
    ASSERT_GT(full, 0u) << key;
    Selection selection, firstOnly;
    for (const Camera& camera : camerasFor(package, random, 20)) {
      for (int b = 0; b < 12; ++b) {
        // Budgets from a handful of vertices to more than the model has.
        const auto budget = static_cast<std::uint64_t>(double(full) * random.logUniform(1e-4, 1.3));
        selectTwoPass(scene, camera, budget, {}, selection);
        expectValidCounts(scene, package, selection);
        const std::uint64_t target = std::min(budget, full);
        // The oracle from the first pass alone predicts the two-pass counts one for one.
        selectTwoPass(scene, camera, budget, {.firstPassOnly = true}, firstOnly);
        std::vector<std::uint32_t> expected = firstOnly.vertexCounts;
        const std::uint64_t left = oracle(scene, firstOnly.importance, budget, expected);
        ++checked;
        if (left == 0) {
          ASSERT_EQ(selection.vertexCounts, expected) << key << " budget " << budget;
          ASSERT_EQ(selection.totalVertices, target) << key << " budget " << budget;
          ++exact;
        } else {
          // No greedy placement exists: the fix-up may trade a hidden object in, and the sum never
          // exceeds the budget.
          ++unreachable;
          EXPECT_LE(selection.totalVertices, target) << key;
          if (selection.totalVertices < target) {
            ++shortOfBudget;
            // On these models that happens only for budgets below every object's minimum, which no
            // selection can meet.
            std::uint32_t smallestMinimum = ~0u;
            for (const std::uint32_t q : scene.minVertices) {
              if (q > 0) smallestMinimum = std::min(smallestMinimum, q);
            }
            EXPECT_LT(target, smallestMinimum) << key;
            // Then nothing hidden fits: every object at zero needs more than what is missing plus
            // all the slack above the shown objects' minimums.
            std::uint64_t slack = 0;
            for (std::size_t i = 0; i < scene.size(); ++i)
              if (selection.vertexCounts[i] > 0)
                slack += selection.vertexCounts[i] - scene.minVertices[i];
            const std::uint64_t missing = target - selection.totalVertices;
            for (std::size_t i = 0; i < scene.size(); ++i) {
              if (selection.vertexCounts[i] == 0 && scene.maxVertices[i] > 0) {
                EXPECT_GT(scene.minVertices[i], missing + slack) << key << " object " << i;
              }
            }
          }
        }
      }
    }
  }
  std::printf(
      "selection cases: %llu by Algorithm 3, %llu by the fix-up, %llu short of an unreachable "
      "budget\n",
      static_cast<unsigned long long>(exact),
      static_cast<unsigned long long>(unreachable - shortOfBudget),
      static_cast<unsigned long long>(shortOfBudget));
  // Almost every case is the plain Algorithm 3 path.
  EXPECT_GT(exact, checked * 9 / 10) << unreachable << " of " << checked << " needed the fix-up";
}

TEST(Selection, FirstPassFollowsEquations2And3) {
  Random random(12);
  for (const char* key : kPackages) {
    const Package& package = test::RuntimePackages::get(key);
    for (const double exponent : {3.0, 2.0}) {
      const LodScene scene = LodScene::fromPackage(package, exponent);
      const SelectionOptions options{.exponent = exponent, .minT = 0.5, .firstPassOnly = true};
      Selection s;
      for (const Camera& camera : camerasFor(package, random, 5)) {
        const std::uint64_t budget = scene.totalMaxVertices() / 10 + 1;
        selectTwoPass(scene, camera, budget, options, s);
        expectValidCounts(scene, package, s);
        double total = 0, largest = 0;
        for (float w : s.importance) {
          total += w;
          largest = std::max(largest, double(w));
        }
        std::uint64_t sum = 0, visible = 0;
        for (std::size_t i = 0; i < scene.size(); ++i) {
          const PackageObject& o = package.object(i);
          // Eq. 2's weight, recomputed in double from the object's box.
          const Vec3d lo{o.boundsMin[0], o.boundsMin[1], o.boundsMin[2]},
              hi{o.boundsMax[0], o.boundsMax[1], o.boundsMax[2]};
          const ViewProjection view(camera);
          const double area = projectedArea(view, lo, hi);
          const double distance =
              std::max(length((lo + hi) * 0.5 - camera.position), camera.nearPlane);
          const double weight = o.triangleCount
                                    ? std::pow(area / distance, exponent) *
                                          std::pow(double(o.triangleCount), 1 - exponent)
                                    : 0;
          // Single precision, and the cube triples the relative error of A / D; tiny far
          // boxes lose more to cancellation, which matters only relative to the largest weight.
          ASSERT_NEAR(s.importance[i], weight, 1e-2 * weight + 1e-6 * largest)
              << key << " object " << i;
          // Eq. 3 from the share.
          const double vc = total > 0 ? double(budget) * s.importance[i] / total : 0;
          const double q = o.minVertexCount, p = o.vertexCount;
          std::uint32_t expected = 0;
          if (vc >= p)
            expected = o.vertexCount;
          else if (vc >= q)
            expected = static_cast<std::uint32_t>(vc);
          else if (q > 0 && vc / q >= options.minT)
            expected = o.minVertexCount;
          // Rounding of the float sum may move a share across an integer: allow one vertex.
          ASSERT_LE(std::abs(double(s.vertexCounts[i]) - double(expected)),
                    expected == 0 || s.vertexCounts[i] == 0 ? 0.0 : 1.0)
              << key << " object " << i << " share " << vc;
          sum += s.vertexCounts[i];
          visible += s.importance[i] > 0;
        }
        EXPECT_EQ(s.firstPassVertices, sum);
        EXPECT_EQ(s.visibleObjects, visible);
      }
    }
  }
}

TEST(Selection, EdgesOfTheBudget) {
  const Package& package = test::RuntimePackages::get("cad");
  const LodScene scene = LodScene::fromPackage(package);
  const Camera camera = orbitPath(test::packageBounds(package), {.frames = 1}).front();
  Selection s;
  selectTwoPass(scene, camera, 0, {}, s);
  EXPECT_EQ(s.totalVertices, 0u);
  EXPECT_EQ(s.totalTriangles, 0u);
  selectTwoPass(scene, camera, scene.totalMaxVertices() * 2, {}, s);
  EXPECT_EQ(s.totalVertices, scene.totalMaxVertices());
  for (std::size_t i = 0; i < scene.size(); ++i) EXPECT_EQ(s.vertexCounts[i], scene.maxVertices[i]);
  EXPECT_EQ(s.totalTriangles, package.header().triangleCount);
}

TEST(Selection, HiddenObjectsTakeOnlyWhatTheVisibleOnesCannot) {
  // Looking away from the model nothing is visible: the budget still fills (Σ = N, as the paper
  // requires), from hidden objects in id order; while visible objects lack vertices, hidden ones
  // get none.
  const Package& package = test::RuntimePackages::get("cad");
  const LodScene scene = LodScene::fromPackage(package);
  const Aabbd bounds = test::packageBounds(package);
  Camera away = Camera::lookAt(bounds.max + bounds.size(), bounds.max + bounds.size() * 2.0,
                               {0, 0, 1}, 60, 800, 600);
  fitClipPlanes(away, bounds);
  Selection s;
  const std::uint64_t budget = scene.totalMaxVertices() / 3;
  selectTwoPass(scene, away, budget, {}, s);
  EXPECT_EQ(s.visibleObjects, 0u);
  EXPECT_EQ(s.totalVertices, budget);
  Camera close = Camera::lookAt(bounds.center() - Vec3d{bounds.size().x * 0.3, 0, 0},
                                bounds.center(), {0, 0, 1}, 50, 800, 600);
  fitClipPlanes(close, bounds);
  selectTwoPass(scene, close, budget / 4, {}, s);
  ASSERT_GT(s.visibleObjects, 0u);
  bool visibleLacking = false;
  std::uint64_t hiddenVertices = 0;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (s.importance[i] > 0 && s.vertexCounts[i] < scene.maxVertices[i]) visibleLacking = true;
    if (!(s.importance[i] > 0)) hiddenVertices += s.vertexCounts[i];
  }
  ASSERT_TRUE(visibleLacking);
  EXPECT_EQ(hiddenVertices, 0u);
  EXPECT_EQ(s.totalVertices, budget / 4);
}

TEST(Selection, ErrorDrivenCountsAreTheFewestUnderThePixelBound) {
  Random random(13);
  for (const char* key : kPackages) {
    const Package& package = test::RuntimePackages::get(key);
    const LodScene scene = LodScene::fromPackage(package);
    Selection s;
    for (const Camera& camera : camerasFor(package, random, 4)) {
      for (const double pixels : {0.5, 2.0, 10.0}) {
        selectByError(scene, camera, pixels, s);
        expectValidCounts(scene, package, s);
        for (std::size_t i = 0; i < scene.size(); ++i) {
          if (!(s.importance[i] > 0)) {
            ASSERT_EQ(s.vertexCounts[i], 0u);
            continue;
          }
          const auto error = package.error(i);
          const std::uint32_t q = scene.minVertices[i], n = s.vertexCounts[i];
          const Vec3d centre{scene.cx[i], scene.cy[i], scene.cz[i]};
          const double distance = std::max(length(centre - camera.position), camera.nearPlane);
          const double toPixels = camera.pixelScale() / distance;
          ASSERT_LE(double(error[n - q]) * toPixels, pixels * (1 + 1e-9)) << key << " " << i;
          if (n > q) {
            ASSERT_GT(double(error[n - 1 - q]) * toPixels, pixels * (1 - 1e-9)) << key << " " << i;
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace lodforge
