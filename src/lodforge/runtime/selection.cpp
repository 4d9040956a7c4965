#include "lodforge/runtime/selection.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "lodforge/simplify/progressive.h"

namespace lodforge {

LodScene LodScene::fromPackage(const Package& package, double exponent) {
  LodScene scene;
  scene.package = &package;
  scene.exponent = exponent;
  const std::size_t n = package.objectCount();
  for (auto* v :
       {&scene.cx, &scene.cy, &scene.cz, &scene.hx, &scene.hy, &scene.hz, &scene.primitiveFactor})
    v->resize(n);
  scene.minVertices.resize(n);
  scene.maxVertices.resize(n);
  scene.levelOffset.resize(n);
  scene.map = package.allMap().data();
  if (package.header().hasUvs()) scene.whole = package.allWhole().data();
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    const PackageObject& o = package.object(i);
    scene.cx[i] = 0.5f * (o.boundsMin[0] + o.boundsMax[0]);
    scene.cy[i] = 0.5f * (o.boundsMin[1] + o.boundsMax[1]);
    scene.cz[i] = 0.5f * (o.boundsMin[2] + o.boundsMax[2]);
    scene.hx[i] = 0.5f * (o.boundsMax[0] - o.boundsMin[0]);
    scene.hy[i] = 0.5f * (o.boundsMax[1] - o.boundsMin[1]);
    scene.hz[i] = 0.5f * (o.boundsMax[2] - o.boundsMin[2]);
    // Eq. 2's primitive term after the 1/α power: (P^β)^(1/α) = P^(β/α) = P^(1 - 1/α), fixed per
    // object, so it is computed once here.
    scene.primitiveFactor[i] =
        o.triangleCount > 0 ? static_cast<float>(std::pow(double(o.triangleCount), 1.0 - exponent))
                            : 0.0f;
    scene.minVertices[i] = o.minVertexCount;
    scene.maxVertices[i] = o.vertexCount;
    scene.levelOffset[i] = o.levelOffset;
  });
  return scene;
}

std::uint64_t LodScene::totalMaxVertices() const {
  return std::accumulate(maxVertices.begin(), maxVertices.end(), std::uint64_t{0});
}

namespace {

// Eq. 2's weight per object, up to the constant factor β^(1/α):
//   w_i = β (A_i / D_i) P_i^β, β = α - 1   =>   w_i^(1/α) = β^(1/α) (A_i/D_i)^(1/α) P_i^(β/α).
// With 1/α = 3 (the paper), α = 1/3 and β = -2/3 < 0: every w_i is negative, and so is every
// w_i^(1/α) (an odd power). β^(1/α) is the same for all objects and cancels between the numerator
// and the sum in Eq. 2, sign included, so the shares use the positive importance
// (A_i/D_i)^(1/α) P_i^(β/α), which also orders objects for Algorithm 3.
// The view as the hot loop reads it, in single precision.
struct ViewConstants {
  float rx, ry, rz, ux, uy, uz, fx, fy, fz;  // right, up, forward
  float ox, oy, oz;                          // camera position
  float tanX, tanY, nearPlane, farPlane, halfWidth, halfHeight;
};

// (A_i / D_i) for objects [begin, end): a plain-array kernel, so that the compiler sees
// unaliased arrays and vectorises it.
void areaOverDistance(std::size_t begin, std::size_t end, const ViewConstants& v,
                      const float* __restrict cx, const float* __restrict cy,
                      const float* __restrict cz, const float* __restrict hx,
                      const float* __restrict hy, const float* __restrict hz,
                      float* __restrict out) {
  const ViewConstants c = v;  // locals, not loads through a reference, inside the loop
  for (std::size_t i = begin; i < end; ++i) {
    const float dx = cx[i] - c.ox, dy = cy[i] - c.oy, dz = cz[i] - c.oz;
    const float area = projectedArea<float>(c.rx, c.ry, c.rz, c.ux, c.uy, c.uz, c.fx, c.fy, c.fz,
                                            c.tanX, c.tanY, c.nearPlane, c.farPlane, c.halfWidth,
                                            c.halfHeight, dx, dy, dz, hx[i], hy[i], hz[i]);
    const float distance = std::max(std::sqrt(dx * dx + dy * dy + dz * dz), c.nearPlane);
    out[i] = area / distance;
  }
}

// (A/D)^(1/α) P^(β/α) in place; the paper's cube without a call to pow.
void applyExponent(std::size_t begin, std::size_t end, bool cube, float exponent,
                   const float* __restrict primitive, float* __restrict importance) {
  if (cube) {
    for (std::size_t i = begin; i < end; ++i) {
      const float r = importance[i];
      importance[i] = r * r * r * primitive[i];
    }
  } else {
    for (std::size_t i = begin; i < end; ++i)
      importance[i] = std::pow(importance[i], exponent) * primitive[i];
  }
}

void computeImportance(const LodScene& scene, const Camera& camera, Selection& out) {
  const std::size_t n = scene.size();
  out.importance.resize(n);
  const ViewProjection view(camera);
  const auto f = [](double x) { return static_cast<float>(x); };
  const ViewConstants constants{
      f(view.right.x),  f(view.right.y),   f(view.right.z),   f(view.up.x),      f(view.up.y),
      f(view.up.z),     f(view.forward.x), f(view.forward.y), f(view.forward.z), f(view.origin.x),
      f(view.origin.y), f(view.origin.z),  f(view.tanX),      f(view.tanY),      f(view.nearPlane),
      f(view.farPlane), f(view.halfWidth), f(view.halfHeight)};
  const bool cube = scene.exponent == 3.0;
  const float exponent = f(scene.exponent);
  // Fixed blocks, each summing its weights for Eq. 2's denominator: the total, and so the
  // selection, is the same whatever the number of threads.
  constexpr std::size_t kBlock = 16384;
  auto& sums = out.workspace.blockSums;
  sums.assign((n + kBlock - 1) / kBlock, 0.0);
  tbb::parallel_for(std::size_t{0}, sums.size(), [&](std::size_t block) {
    const std::size_t begin = block * kBlock, end = std::min(n, begin + kBlock);
    areaOverDistance(begin, end, constants, scene.cx.data(), scene.cy.data(), scene.cz.data(),
                     scene.hx.data(), scene.hy.data(), scene.hz.data(), out.importance.data());
    applyExponent(begin, end, cube, exponent, scene.primitiveFactor.data(), out.importance.data());
    double sum = 0;
    for (std::size_t i = begin; i < end; ++i) sum += double(out.importance[i]);
    sums[block] = sum;
  });
  out.importanceTotal = std::accumulate(sums.begin(), sums.end(), 0.0);
}

// Eq. 2 then Eq. 3.
void firstPass(const LodScene& scene, std::uint64_t budget, double minT, Selection& out) {
  const std::size_t n = scene.size();
  out.vertexCounts.resize(n);
  const double total = out.importanceTotal;
  const double scale = total > 0 ? static_cast<double>(budget) / total : 0.0;
  std::tie(out.firstPassVertices, out.visibleObjects) = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 16384), std::pair<std::uint64_t, std::uint64_t>{0, 0},
      [&](const tbb::blocked_range<std::size_t>& r, std::pair<std::uint64_t, std::uint64_t> acc) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
          const double vc = scale * double(out.importance[i]);  // Eq. 2
          const double lo = scene.minVertices[i], hi = scene.maxVertices[i];
          std::uint32_t mapped;  // Eq. 3
          if (vc >= hi)
            mapped = scene.maxVertices[i];
          else if (vc >= lo)
            mapped = static_cast<std::uint32_t>(vc);
          else if (lo > 0 && vc / lo >= minT)
            mapped = scene.minVertices[i];
          else
            mapped = 0;
          out.vertexCounts[i] = mapped;
          acc.first += mapped;
          acc.second += out.importance[i] > 0 ? 1u : 0u;
        }
        return acc;
      },
      [](auto a, auto b) {
        return std::pair{a.first + b.first, a.second + b.second};
      });
}

// Gives `remaining` vertices to objects in `order` (most important first): an object already
// shown grows within its range; one at zero takes at least its minimum. Returns what is left.
std::uint64_t distribute(const LodScene& scene, std::span<const std::uint32_t> order,
                         std::uint64_t remaining, std::vector<std::uint32_t>& vc) {
  for (std::uint32_t i : order) {
    if (remaining == 0) break;
    const std::uint32_t lo = scene.minVertices[i], hi = scene.maxVertices[i];
    if (vc[i] >= hi) continue;
    if (vc[i] == 0 && (remaining < lo || hi == 0)) continue;
    const std::uint64_t give = std::min<std::uint64_t>(remaining, hi - vc[i]);
    vc[i] += static_cast<std::uint32_t>(give);
    remaining -= give;
  }
  return remaining;
}

// The last few vertices when every shown object is full and every object at zero needs more
// than is left: show the object at zero with the smallest minimum (the most important among
// equals) and take the overshoot back from the least important shown objects, none below its
// minimum. `order` runs from most to least important. Returns what is still left: nonzero only
// when no such exchange exists (say, a budget smaller than every object's minimum), and then
// the sum stays below N, never above.
std::uint64_t settle(const LodScene& scene, std::span<const float> importance,
                     std::span<const std::uint32_t> order, std::uint64_t left,
                     std::vector<std::uint32_t>& vc) {
  while (left > 0) {
    std::uint64_t slack = 0;
    std::size_t pick = vc.size();
    for (std::size_t i = 0; i < vc.size(); ++i) {
      const std::uint32_t lo = scene.minVertices[i];
      if (vc[i] > 0) {
        slack += vc[i] - lo;
      } else if (scene.maxVertices[i] > 0 &&
                 (pick == vc.size() || lo < scene.minVertices[pick] ||
                  (lo == scene.minVertices[pick] && importance[i] > importance[pick]))) {
        pick = i;
      }
    }
    if (pick == vc.size()) return left;
    const std::uint32_t lo = scene.minVertices[pick];
    if (lo <= left) {  // an object the walk did not reach (hidden, when dropping)
      const auto give =
          static_cast<std::uint32_t>(std::min<std::uint64_t>(left, scene.maxVertices[pick]));
      vc[pick] = give;
      left -= give;
      continue;
    }
    if (lo - left > slack) return left;
    std::uint64_t over = lo - left;
    const auto withdraw = [&](std::uint32_t i) {
      if (vc[i] <= scene.minVertices[i]) return;
      const std::uint64_t take = std::min<std::uint64_t>(over, vc[i] - scene.minVertices[i]);
      vc[i] -= static_cast<std::uint32_t>(take);
      over -= take;
    };
    for (std::size_t j = order.size(); j-- > 0 && over > 0;) withdraw(order[j]);
    // Objects outside `order` given vertices above count towards the slack too.
    for (std::uint32_t i = 0; i < vc.size() && over > 0; ++i) withdraw(i);
    vc[pick] = lo;
    left = 0;
  }
  return 0;
}

// Algorithm 3 needs the objects in importance order only up to the k where the prefix sums
// of VDif cross ΔN. So instead of sorting all of them, one parallel pass partitions object ids
// by the top 11 bits of a rank key (a one-digit radix sort) and sums VDif per bucket; the
// prefix sums and the search for k run over the 2,048 bucket sums, every object of a bucket
// before k's is settled in bulk, and only the buckets the walk actually enters are sorted.
// The result is the same as sorting everything (tests compare with a full sort).
constexpr unsigned kRankBits = 11;
// 2,048 buckets by key, and upward one more after them for the objects outside the view, which
// go by id (the partition keeps that order, so their bucket needs no sort).
constexpr std::size_t kKeyBuckets = std::size_t{1} << kRankBits;
constexpr std::size_t kRankBuckets = kKeyBuckets + 1;
constexpr std::size_t kHiddenBucket = kKeyBuckets;

// Smaller keys come first: descending importance (upward), or ascending (downward). Objects
// with no importance (outside the view) go last upward and are left out downward.
inline std::uint32_t rankKey(float importance, bool descending) {
  std::uint32_t bits;
  std::memcpy(&bits, &importance, sizeof bits);
  return descending ? (importance > 0 ? ~bits : 0xFFFFFFFFu) : bits;
}

inline std::size_t rankBucket(float importance, bool descending) {
  if (descending && !(importance > 0)) return kHiddenBucket;
  return rankKey(importance, descending) >> (32 - kRankBits);
}

struct RankBuckets {
  std::span<const std::uint32_t> ids;     // object ids grouped by bucket, by id within one
  std::span<const std::uint64_t> start;   // kRankBuckets + 1
  std::span<const std::uint64_t> weight;  // per bucket: Σ VDif
};

// The partition, in parallel over fixed chunks of objects (per-chunk histograms, then each chunk
// scatters its ids), so the grouping is the same whatever the thread count.
template <class Weight>
RankBuckets partitionByRank(std::span<const float> importance, bool descending, Weight weightOf,
                            Selection::Workspace& work) {
  const std::size_t n = importance.size();
  const std::size_t chunks = std::clamp<std::size_t>(n / 4096, 1, 64);
  const auto chunkBegin = [&](std::size_t c) { return n * c / chunks; };
  work.chunkCounts.assign(chunks * kRankBuckets, 0);
  work.chunkWeights.assign(chunks * kRankBuckets, 0);
  const auto included = [&](std::size_t i) { return descending || importance[i] > 0; };
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    std::uint64_t* counts = work.chunkCounts.data() + c * kRankBuckets;
    std::uint64_t* weights = work.chunkWeights.data() + c * kRankBuckets;
    for (std::size_t i = chunkBegin(c); i < chunkBegin(c + 1); ++i) {
      if (!included(i)) continue;
      const std::size_t bucket = rankBucket(importance[i], descending);
      ++counts[bucket];
      weights[bucket] += weightOf(static_cast<std::uint32_t>(i));
    }
  });
  // Exclusive offsets, bucket-major then chunk: ids of a bucket stay in id order.
  work.bucketStart.assign(kRankBuckets + 1, 0);
  work.bucketWeight.assign(kRankBuckets, 0);
  std::uint64_t at = 0;
  for (std::size_t b = 0; b < kRankBuckets; ++b) {
    work.bucketStart[b] = at;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::uint64_t count = work.chunkCounts[c * kRankBuckets + b];
      work.chunkCounts[c * kRankBuckets + b] = at;
      at += count;
      work.bucketWeight[b] += work.chunkWeights[c * kRankBuckets + b];
    }
  }
  work.bucketStart[kRankBuckets] = at;
  work.bucketIds.resize(at);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    std::uint64_t* next = work.chunkCounts.data() + c * kRankBuckets;
    for (std::size_t i = chunkBegin(c); i < chunkBegin(c + 1); ++i) {
      if (!included(i)) continue;
      const std::size_t bucket = rankBucket(importance[i], descending);
      work.bucketIds[next[bucket]++] = static_cast<std::uint32_t>(i);
    }
  });
  return {work.bucketIds, work.bucketStart, work.bucketWeight};
}

// Appends the ids of one bucket to `out` in exact rank order (key, then id).
void appendSortedBucket(const RankBuckets& buckets, std::size_t b,
                        std::span<const float> importance, bool descending,
                        std::vector<std::uint64_t>& keys, std::vector<std::uint32_t>& out) {
  const auto ids = buckets.ids.subspan(buckets.start[b], buckets.start[b + 1] - buckets.start[b]);
  if (b == kHiddenBucket) {
    out.insert(out.end(), ids.begin(), ids.end());
    return;
  }
  keys.resize(ids.size());
  for (std::size_t j = 0; j < ids.size(); ++j)
    keys[j] = std::uint64_t{rankKey(importance[ids[j]], descending)} << 32 | ids[j];
  std::sort(keys.begin(), keys.end());
  for (const std::uint64_t key : keys) out.push_back(static_cast<std::uint32_t>(key));
}

// One bucket in rank order, in the workspace's `order`.
std::span<const std::uint32_t> sortedBucket(const RankBuckets& buckets, std::size_t b,
                                            std::span<const float> importance, bool descending,
                                            Selection::Workspace& work) {
  work.order.clear();
  appendSortedBucket(buckets, b, importance, descending, work.keys, work.order);
  return work.order;
}

// Every partitioned object in rank order (all buckets sorted), in the workspace's `order`.
std::span<const std::uint32_t> wholeOrder(const RankBuckets& buckets,
                                          std::span<const float> importance, bool descending,
                                          Selection::Workspace& work) {
  work.order.clear();
  for (std::size_t b = 0; b < kRankBuckets; ++b)
    appendSortedBucket(buckets, b, importance, descending, work.keys, work.order);
  return work.order;
}

// Sets every object of buckets [first, last) to `value(i)`, in parallel.
template <class Value>
void settleBuckets(const RankBuckets& buckets, std::size_t first, std::size_t last, Value value,
                   std::vector<std::uint32_t>& vc) {
  const std::uint64_t begin = buckets.start[first], end = buckets.start[last];
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(begin, end, 16384),
                    [&](const tbb::blocked_range<std::uint64_t>& range) {
                      for (std::uint64_t j = range.begin(); j < range.end(); ++j) {
                        const std::uint32_t i = buckets.ids[j];
                        vc[i] = value(i);
                      }
                    });
}

// N' < N (Algorithm 3 upward): the most important objects take their maximum while the prefix
// sums of VDif = max - vc stay within ΔN; beyond the paper, the walk goes on giving the rest to
// the next objects in order (partially, or whole when they fit), hidden objects last. Returns
// what could not be placed.
std::uint64_t raise(const LodScene& scene, const std::vector<float>& importance, std::uint64_t gap,
                    Selection& out) {
  auto& vc = out.vertexCounts;
  const auto lacking = [&](std::uint32_t i) -> std::uint64_t {
    return scene.maxVertices[i] - std::min(vc[i], scene.maxVertices[i]);
  };
  const RankBuckets buckets = partitionByRank(importance, true, lacking, out.workspace);
  std::size_t b = 0;
  while (b < kRankBuckets && buckets.weight[b] <= gap) gap -= buckets.weight[b++];
  settleBuckets(
      buckets, 0, b, [&](std::uint32_t i) { return scene.maxVertices[i]; }, vc);
  for (; b < kRankBuckets && gap > 0; ++b) {
    if (buckets.start[b] == buckets.start[b + 1]) continue;
    gap = distribute(scene, sortedBucket(buckets, b, importance, true, out.workspace), gap, vc);
  }
  return gap;
}

// N' > N (Algorithm 3 downward): the least important shown objects drop to zero while the prefix
// sums of their counts stay below the excess; beyond the paper, the overshoot of the last one
// dropped goes back to the most important objects first. Returns what could not be placed.
std::uint64_t lower(const LodScene& scene, const std::vector<float>& importance,
                    std::uint64_t excess, Selection& out) {
  auto& vc = out.vertexCounts;
  const RankBuckets buckets = partitionByRank(
      importance, false, [&](std::uint32_t i) -> std::uint64_t { return vc[i]; }, out.workspace);
  std::uint64_t dropped = 0;
  std::size_t b = 0;
  while (b < kRankBuckets && dropped + buckets.weight[b] <= excess) dropped += buckets.weight[b++];
  settleBuckets(
      buckets, 0, b, [](std::uint32_t) { return 0u; }, vc);
  if (dropped < excess && b < kRankBuckets) {
    for (const std::uint32_t i : sortedBucket(buckets, b, importance, false, out.workspace)) {
      if (dropped >= excess) break;
      dropped += std::exchange(vc[i], 0u);
    }
  }
  std::uint64_t giveBack = dropped - excess;
  for (std::size_t top = kRankBuckets; top-- > 0 && giveBack > 0;) {
    if (buckets.start[top] == buckets.start[top + 1]) continue;
    sortedBucket(buckets, top, importance, false, out.workspace);
    std::vector<std::uint32_t>& mostImportantFirst = out.workspace.order;
    std::reverse(mostImportantFirst.begin(), mostImportantFirst.end());
    giveBack = distribute(scene, mostImportantFirst, giveBack, vc);
  }
  return giveBack;
}

// Algorithm 3, then the partial allocation that makes Σ vc == N.
void secondPass(const LodScene& scene, std::uint64_t budget, Selection& out) {
  const std::uint64_t current = out.firstPassVertices;
  const std::uint64_t target = std::min(budget, scene.totalMaxVertices());
  if (current == target) return;
  const bool up = current < target;
  const std::uint64_t left = up ? raise(scene, out.importance, target - current, out)
                                : lower(scene, out.importance, current - target, out);
  if (left == 0) return;
  // Rare (tiny budgets): trade an object at zero in, which needs the whole order, most
  // important first; the walk's partition still stands in the workspace.
  auto& work = out.workspace;
  const RankBuckets buckets{work.bucketIds, work.bucketStart, work.bucketWeight};
  wholeOrder(buckets, out.importance, up, work);
  if (!up) std::reverse(work.order.begin(), work.order.end());
  settle(scene, out.importance, work.order, left, out.vertexCounts);
}

// A textured object's count rounds down to a whole one (a point's wedges go together): the sum
// then falls short of N by less than the wedges of one point per textured object.
void roundDownToWhole(const LodScene& scene, Selection& out) {
  if (!scene.whole) return;
  tbb::parallel_for(std::size_t{0}, scene.size(), [&](std::size_t i) {
    std::uint32_t& v = out.vertexCounts[i];
    if (v != 0) v = scene.whole[scene.levelOffset[i] + (v - scene.minVertices[i])];
  });
}

// tc_i = map(vc_i), looked up only where vc_i changed since the last frame (a few percent of
// the objects along a smooth path): each lookup is a cache miss in a table of the package's size.
void lookUpTriangleCounts(const LodScene& scene, Selection& out) {
  const std::size_t n = scene.size();
  auto& previous = out.workspace.previousVertexCounts;
  const bool coherent = out.workspace.previousMap == scene.map && previous.size() == n &&
                        out.triangleCounts.size() == n;
  out.triangleCounts.resize(n);
  const std::uint32_t* map = scene.map;
  std::tie(out.totalVertices, out.totalTriangles) = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 16384), std::pair<std::uint64_t, std::uint64_t>{0, 0},
      [&](const tbb::blocked_range<std::size_t>& r, std::pair<std::uint64_t, std::uint64_t> acc) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
          const std::uint32_t v = out.vertexCounts[i];
          if (!coherent || previous[i] != v) {
            // A count of 0 draws nothing.
            out.triangleCounts[i] =
                v == 0 ? 0 : map[scene.levelOffset[i] + (v - scene.minVertices[i])];
          }
          acc.first += v;
          acc.second += out.triangleCounts[i];
        }
        return acc;
      },
      [](auto a, auto b) {
        return std::pair{a.first + b.first, a.second + b.second};
      });
  out.workspace.previousMap = scene.map;
}

// Last frame's counts move aside (every entry of vertexCounts is rewritten this frame), so
// lookUpTriangleCounts() can see which changed without copying them.
void keepLastFrame(Selection& out) {
  std::swap(out.vertexCounts, out.workspace.previousVertexCounts);
}

double millisecondsSince(std::chrono::steady_clock::time_point& start) {
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - start).count();
  start = now;
  return ms;
}

}  // namespace

void selectTwoPass(const LodScene& scene, const Camera& camera, std::uint64_t budget,
                   const SelectionOptions& options, Selection& out) {
  assert(scene.package && options.exponent == scene.exponent);
  auto clock = std::chrono::steady_clock::now();
  keepLastFrame(out);
  computeImportance(scene, camera, out);
  out.timings.importance = millisecondsSince(clock);
  firstPass(scene, budget, options.minT, out);
  out.timings.firstPass = millisecondsSince(clock);
  if (!options.firstPassOnly) secondPass(scene, budget, out);
  roundDownToWhole(scene, out);
  out.timings.secondPass = millisecondsSince(clock);
  lookUpTriangleCounts(scene, out);
  out.timings.finish = millisecondsSince(clock);
}

void selectByError(const LodScene& scene, const Camera& camera, double pixels, Selection& out) {
  auto clock = std::chrono::steady_clock::now();
  keepLastFrame(out);
  computeImportance(scene, camera, out);
  out.timings.importance = millisecondsSince(clock);
  const std::size_t n = scene.size();
  out.vertexCounts.resize(n);
  const double pixelScale = camera.pixelScale();
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    if (out.importance[i] <= 0) {
      out.vertexCounts[i] = 0;
      return;
    }
    // An error e at distance D covers e * pixelScale / D pixels.
    const Vec3d d = Vec3d{scene.cx[i], scene.cy[i], scene.cz[i]} - camera.position;
    const double distance = std::max(length(d), camera.nearPlane);
    const double allowed = pixels * distance / pixelScale;
    out.vertexCounts[i] =
        vertexCountForError(scene.package->error(i), scene.minVertices[i], allowed);
  });
  out.firstPassVertices = 0;
  out.visibleObjects = static_cast<std::uint64_t>(
      std::count_if(out.importance.begin(), out.importance.end(), [](float w) { return w > 0; }));
  roundDownToWhole(scene, out);
  out.timings.firstPass = millisecondsSince(clock);
  out.timings.secondPass = 0;
  lookUpTriangleCounts(scene, out);
  out.timings.finish = millisecondsSince(clock);
}

}  // namespace lodforge
