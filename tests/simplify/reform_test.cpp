#include "lodforge/simplify/reform.h"

#include <gtest/gtest.h>

#include "lodforge/core/random.h"
#include "lodforge/core/threads.h"
#include "lodforge/generate/cad.h"
#include "lodforge/simplify/builder.h"
#include "lodforge/simplify/package.h"
#include "test_support.h"

namespace lodforge {
namespace {

// A package of generated CAD parts, built once for all tests here. Its folder goes when the
// package is open (the mapping keeps the file; a folder that outlived the tests was left in
// /tmp by every run).
const Package& parts() {
  static const Package package = [] {
    const test::TempDir dir;
    EXPECT_TRUE(generateCad({.objects = 300, .seed = 21}, dir.file("parts.glb")).ok());
    EXPECT_TRUE(buildPackage(dir.file("parts.glb"), dir.file("parts.lfp")).ok());
    Result<Package> p = Package::open(dir.file("parts.lfp"));
    EXPECT_TRUE(p.ok()) << p.error().message;
    return std::move(p.value());
  }();
  return package;
}

TEST(Reform, ParallelSelectionEqualsObjectByObject) {
  const Package& package = parts();
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Random random(seed);
    // A random subset in random order, random levels, random vertex bases.
    std::vector<std::uint32_t> objects, counts, bases;
    for (std::uint32_t o = 0; o < package.objectCount(); ++o) {
      if (random.uniform() < 0.6) objects.push_back(o);
    }
    for (std::size_t i = objects.size(); i > 1; --i)
      std::swap(objects[i - 1], objects[random.below(i)]);
    std::vector<std::uint64_t> starts = {0};
    std::uint32_t base = 0;
    for (std::uint32_t o : objects) {
      const PackageObject& r = package.object(o);
      counts.push_back(r.minVertexCount + static_cast<std::uint32_t>(
                                              random.below(r.vertexCount - r.minVertexCount + 1)));
      bases.push_back(base);
      base += counts.back();
      starts.push_back(starts.back() + package.trianglesAt(o, counts.back()));
    }
    std::vector<std::uint32_t> expected(3 * starts.back());
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const auto triangles = package.triangles(objects[i]).first(3 * (starts[i + 1] - starts[i]));
      reformObject(triangles, package.ecol(objects[i]), counts[i], bases[i],
                   std::span(expected).subspan(3 * starts[i], triangles.size()));
    }
    for (unsigned threads : {1u, 2u}) {
      const ThreadLimit limit(threads);
      std::vector<std::uint32_t> actual(expected.size(), ~0u);
      reformSelection(ReformSource::of(package), {objects, counts, starts, bases}, actual);
      ASSERT_EQ(actual, expected) << "seed " << seed << " threads " << threads;
    }
  }
}

TEST(Reform, EveryCornerLandsBelowItsObjectsCount) {
  const Package& package = parts();
  std::vector<std::uint32_t> objects, counts, bases;
  std::vector<std::uint64_t> starts = {0};
  for (std::uint32_t o = 0; o < package.objectCount(); ++o) {
    objects.push_back(o);
    counts.push_back(package.object(o).minVertexCount);  // the simplest level everywhere
    bases.push_back(0);
    starts.push_back(starts.back() + package.trianglesAt(o, counts.back()));
  }
  // Without triangles at the simplest level the check below would pass on nothing.
  ASSERT_GT(starts.back(), 0u);
  std::vector<std::uint32_t> out(3 * starts.back());
  reformSelection(ReformSource::of(package), {objects, counts, starts, bases}, out);
  for (std::size_t i = 0; i < objects.size(); ++i) {
    for (std::uint64_t c = 3 * starts[i]; c < 3 * starts[i + 1]; ++c) ASSERT_LT(out[c], counts[i]);
  }
}

}  // namespace
}  // namespace lodforge
