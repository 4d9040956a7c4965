#include "lodforge/simplify/progressive.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>

#include "lodforge/core/distance.h"
#include "lodforge/core/quadric.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace lodforge {

std::uint32_t ProgressiveMesh::vertexCountForError(float wanted) const {
  // error[] is non-increasing in n: the first index whose error fits is the answer.
  const auto it = std::find_if(error.begin(), error.end(), [&](float e) { return e <= wanted; });
  return q + static_cast<std::uint32_t>(it - error.begin());
}

std::uint64_t progressiveBuildBytes(std::uint64_t vertices, std::uint64_t triangles) {
  // Per vertex: quadric 80, position and self cost 32, incidence ~36, ranking 8, flags and
  // stamps 6, error 8, the rearranged output and permutation ~48 (boundary counts reuse them).
  // Per triangle: corners 12, removal order 4, rearranged output and permutation 16, Melax's
  // face normals 24, lists of live triangles and new neighbours ~8.
  return vertices * 220 + triangles * 64 + 4096;
}

namespace {

constexpr std::uint32_t kNone = ~0u;
// Each pass collapses at most this share of the ranked candidates (the cheapest ones): small
// enough that costs stay close to a global order, large enough that passes stay few. 0.2 keeps
// the distance to the original within ~1.2x of meshoptimizer's at 10 % and 1 % (bench_simplify)
// at about 0.4x its speed; 1.0 would be ~10 % faster and clearly worse in between.
constexpr double kPassShare = 0.2;
constexpr std::size_t kBuckets = 32;  // cost buckets per pass, each walked in vertex order

// Puts buckets [firstBucket, lastBucket) of `bucket` elements each (the share ends at `share`)
// in cost order among themselves, leaving each bucket unsorted: selections, not a sort.
template <class It>
void partitionBuckets(It begin, std::size_t firstBucket, std::size_t lastBucket, std::size_t bucket,
                      std::size_t share) {
  if (lastBucket - firstBucket < 2) return;
  const std::size_t middle = firstBucket + (lastBucket - firstBucket) / 2;
  std::nth_element(begin + static_cast<std::ptrdiff_t>(firstBucket * bucket),
                   begin + static_cast<std::ptrdiff_t>(middle * bucket),
                   begin + static_cast<std::ptrdiff_t>(std::min(share, lastBucket * bucket)));
  partitionBuckets(begin, firstBucket, middle, bucket, share);
  partitionBuckets(begin, middle, lastBucket, bucket, share);
}

// What ranking reads of a neighbour, in one 32-byte load: its position and the cost of its own
// quadric there (Q_v(p_v)).
struct RankPoint {
  double x, y, z, selfCost;
};

// Collapses happen in passes over flat arrays (as meshoptimizer does), not through one global
// priority queue: each pass ranks every vertex's cheapest valid-looking collapse, buckets them
// by cost, and applies the cheapest fifth that do not touch one another, in cost order. Collapses
// in a pass never share a neighbourhood, so every validity check sees the current mesh, and the
// recorded sequence is a true collapse sequence.
class Simplifier {
 public:
  Simplifier(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices,
             const ProgressiveOptions& options)
      : positions_(positions),
        indices_(indices),
        options_(options),
        vertexCount_(static_cast<std::uint32_t>(positions.size())),
        triangleCount_(static_cast<std::uint32_t>(indices.size() / 3)) {}

  void classifyBoundary();
  void computeQuadrics();
  void collapseAll();
  ProgressiveMesh rearrange(std::span<const Vec3f> normals, std::span<const Rgba8> colors) const;

 private:
  Vec3d position(std::uint32_t v) const {
    const RankPoint& r = rankPoints_[v];
    return {r.x, r.y, r.z};
  }
  // The dead mark shares the cache line the corners are read from anyway.
  bool alive(std::uint32_t t) const { return corners_[t][0] != kNone; }
  bool contains(std::uint32_t t, std::uint32_t v) const {
    return corners_[t][0] == v || corners_[t][1] == v || corners_[t][2] == v;
  }
  // The triangles around v as of the pass start; some may have died since (check alive()).
  std::span<const std::uint32_t> around(std::uint32_t v) const {
    return std::span(incident_).subspan(incidentStart_[v], incidentCount_[v]);
  }
  bool allowed(std::uint32_t from, std::uint32_t to) const;
  void buildIncidence();
  void rankCollapses();
  float cost(std::uint32_t from, std::uint32_t to) const;
  bool valid(std::uint32_t from, std::uint32_t to);
  // The cheapest valid, untouched target of `from` (its ranked best first); kNone if none.
  std::uint32_t validTarget(std::uint32_t from, float bestCost);
  void collapse(std::uint32_t from, std::uint32_t to);
  void markChanged(std::uint32_t from, std::uint32_t to);
  void rankNewNeighbours();

  std::span<const Vec3f> positions_;
  std::span<const std::uint32_t> indices_;
  ProgressiveOptions options_;
  std::uint32_t vertexCount_, triangleCount_;

  std::vector<RankPoint> rankPoints_;                  // positions in double + self costs
  std::vector<std::array<std::uint32_t, 3>> corners_;  // current (re-formed); dead: all kNone
  std::vector<std::uint8_t> locked_;                   // Q: boundary or non-manifold
  std::vector<std::uint8_t> removed_;                  // per vertex: collapsed already
  std::vector<Quadric> quadrics_;
  std::vector<double> vertexError_;  // error carried by each live vertex
  std::vector<Vec3d> faceNormals_;   // per pass, for Melax's cost

  // Per pass: vertex -> live triangles (CSR), and each vertex's best collapse.
  std::vector<std::uint32_t> incidentStart_, incidentCount_, incident_;
  std::vector<std::uint32_t> liveVertices_;  // not collapsed yet
  std::vector<float> bestCost_;
  std::vector<std::uint32_t> bestTarget_;
  std::vector<std::uint8_t> dirty_;  // must be re-ranked next pass
  // (vertex, new neighbour): the one new cost to compare next pass.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> newNeighbour_;
  std::vector<std::uint32_t> live_;
  std::vector<std::uint32_t> active_;         // vertices that may still collapse
  std::vector<std::uint32_t> nearTo_, seen_;  // stamps for valid()
  std::uint32_t stampToken_ = 0;
  std::vector<std::uint32_t> touched_;  // pass number that last touched the vertex
  std::uint32_t pass_ = 0;
  float passLimit_ = 0;  // the dearest cost this pass may collapse

  // The record of collapses, in order.
  std::vector<std::uint32_t> collapsed_;         // vertex removed by collapse k
  std::vector<std::uint32_t> target_;            // per vertex: what it collapsed into
  std::vector<std::uint32_t> removedTriangles_;  // in order of removal
  std::vector<std::uint32_t> trianglesAfter_;    // triangle count after collapse k
  std::vector<float> errorAfter_;                // monotone error after collapse k
  double maxError_ = 0;
};

void Simplifier::classifyBoundary() {
  rankPoints_.resize(vertexCount_);
  for (std::uint32_t v = 0; v < vertexCount_; ++v) {
    const Vec3d p = toDouble(positions_[v]);
    rankPoints_[v] = {p.x, p.y, p.z, 0};
  }
  corners_.resize(triangleCount_);
  locked_.assign(vertexCount_, 0);
  removed_.assign(vertexCount_, 0);
  target_.assign(vertexCount_, kNone);
  vertexError_.assign(vertexCount_, 0.0);
  touched_.assign(vertexCount_, 0);
  nearTo_.assign(vertexCount_, 0);
  seen_.assign(vertexCount_, 0);
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      corners_[t][k] = indices_[3 * t + k];
      assert(corners_[t][k] < vertexCount_);
    }
    assert(corners_[t][0] != corners_[t][1] && corners_[t][1] != corners_[t][2] &&
           corners_[t][0] != corners_[t][2]);
  }
  // Q: endpoints of boundary edges (one triangle) and of non-manifold edges (three or more).
  // Each triangle around u holds the edge u-w for exactly one other corner w, as the corner
  // after or before u, so counting the corners around u counts the triangles on each edge u-w.
  // Every edge is seen from both ends, so each end locks itself.
  buildIncidence();
  std::vector<std::uint32_t> edgeCount(vertexCount_, 0);
  for (std::uint32_t u = 0; u < vertexCount_; ++u) {
    const auto fan = around(u);
    for (std::uint32_t t : fan) {
      for (std::uint32_t w : corners_[t]) edgeCount[w] = 0;
    }
    for (std::uint32_t t : fan) {
      for (std::uint32_t w : corners_[t]) ++edgeCount[w];
    }
    for (std::uint32_t t : fan) {
      for (std::uint32_t w : corners_[t]) {
        if (w != u && edgeCount[w] != 2) locked_[u] = 1;
      }
    }
  }
}

void Simplifier::computeQuadrics() {
  quadrics_.assign(vertexCount_, Quadric{});
  for (const auto& c : corners_) {
    const Vec3d a = position(c[0]), b = position(c[1]), d = position(c[2]);
    const Vec3d n = cross(b - a, d - a);
    const double twiceArea = length(n);
    if (twiceArea <= 0) continue;
    // Area-weighted planes: large faces resist being moved more than slivers (CAD tessellations
    // mix both).
    const Quadric plane = Quadric::fromPlane(n / twiceArea, a, 0.5 * twiceArea);
    for (std::uint32_t v : c) quadrics_[v] += plane;
  }
  for (std::uint32_t v = 0; v < vertexCount_; ++v)
    rankPoints_[v].selfCost = quadrics_[v].evaluate(position(v));
}

bool Simplifier::allowed(std::uint32_t from, std::uint32_t to) const {
  // Eq. 1: a boundary vertex never moves; an edge between two is never collapsed.
  if (locked_[from]) return false;
  if (options_.direction == CollapseDirection::kCheaper) return true;
  // Eq. 1 literally: the lower index moves unless it is a boundary vertex.
  return from < to || locked_[to];
}

void Simplifier::buildIncidence() {
  // Only the live triangles and vertices: the lists shrink pass after pass, and so does this
  // work. The first pass reuses the incidence that classifyBoundary() built.
  if (live_.empty()) {
    live_.resize(triangleCount_);
    for (std::uint32_t t = 0; t < triangleCount_; ++t) live_[t] = t;
    liveVertices_.resize(vertexCount_);
    for (std::uint32_t v = 0; v < vertexCount_; ++v) liveVertices_[v] = v;
    incidentStart_.resize(vertexCount_);
    incidentCount_.resize(vertexCount_);
  } else if (pass_ == 1) {
    return;
  } else {
    std::erase_if(live_, [&](std::uint32_t t) { return !alive(t); });
    std::erase_if(liveVertices_, [&](std::uint32_t v) { return removed_[v] != 0; });
  }
  for (std::uint32_t v : liveVertices_) incidentCount_[v] = 0;
  for (std::uint32_t t : live_) {
    for (std::uint32_t v : corners_[t]) ++incidentCount_[v];
  }
  std::uint32_t end = 0;
  for (std::uint32_t v : liveVertices_) {
    end += incidentCount_[v];
    incidentStart_[v] = end;  // filled backwards below, so it ends at the start
  }
  incident_.resize(end);
  // Backwards, so that each fan lists its triangles in increasing order.
  for (auto t = live_.rbegin(); t != live_.rend(); ++t) {
    for (std::uint32_t v : corners_[*t]) incident_[--incidentStart_[v]] = *t;
  }
  if (options_.cost == CollapseCost::kMelax) {
    faceNormals_.resize(triangleCount_);
    tbb::parallel_for(std::size_t{0}, live_.size(), [&](std::size_t i) {
      const std::uint32_t t = live_[i];
      const Vec3d a = position(corners_[t][0]), b = position(corners_[t][1]),
                  c = position(corners_[t][2]);
      faceNormals_[t] = normalizeOr(cross(b - a, c - a), Vec3d{});
    });
  }
}

float Simplifier::cost(std::uint32_t from, std::uint32_t to) const {
  if (options_.cost == CollapseCost::kQuadric) {
    const Quadric q = quadrics_[from] + quadrics_[to];
    return static_cast<float>(std::max(0.0, q.evaluate(position(to))));
  }
  // Melax (1998): edge length times the largest angle between a face around `from` and the
  // closest-facing face on the edge.
  double curvature = 0;
  const auto fan = around(from);
  for (std::uint32_t t : fan) {
    if (!alive(t)) continue;
    double smallest = 1;
    for (std::uint32_t s : fan) {
      if (alive(s) && contains(s, to))
        smallest = std::min(smallest, (1 - dot(faceNormals_[t], faceNormals_[s])) / 2);
    }
    curvature = std::max(curvature, smallest);
  }
  return static_cast<float>(length(position(from) - position(to)) * curvature);
}

void Simplifier::rankCollapses() {
  if (bestCost_.empty()) {
    bestCost_.assign(vertexCount_, 0);
    bestTarget_.assign(vertexCount_, kNone);
    dirty_.assign(vertexCount_, 1);
  }
  // Only vertices whose cost inputs changed last pass (Melax's cost looks at whole fans, so
  // it re-ranks everything).
  const bool all = options_.cost == CollapseCost::kMelax;
  if (active_.empty() && pass_ == 1) {
    for (std::uint32_t u = 0; u < vertexCount_; ++u) {
      if (!locked_[u]) active_.push_back(u);
    }
  } else {
    active_.erase(std::remove_if(active_.begin(), active_.end(),
                                 [&](std::uint32_t u) { return removed_[u] != 0; }),
                  active_.end());
  }
  rankNewNeighbours();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, active_.size(), 512),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t a = range.begin(); a < range.end(); ++a) {
                        const std::uint32_t u = active_[a];
                        if (!all && !dirty_[u]) continue;
                        dirty_[u] = 0;
                        bestTarget_[u] = kNone;
                        // Each neighbour once: the corner after u in each triangle of its fan (an
                        // interior vertex of a consistently oriented manifold sees every neighbour
                        // exactly so).
                        float best = std::numeric_limits<float>::max();
                        const Quadric& q = quadrics_[u];
                        for (std::uint32_t t : around(u)) {
                          const auto& c = corners_[t];
                          const std::uint32_t v = c[0] == u ? c[1] : (c[1] == u ? c[2] : c[0]);
                          if (!allowed(u, v)) continue;
                          // (Q_u + Q_v)(p_v) = Q_u(p_v) + Q_v(p_v); the second term is cached per
                          // vertex.
                          const float cost =
                              options_.cost == CollapseCost::kQuadric
                                  ? static_cast<float>(std::max(
                                        0.0, q.evaluate(position(v)) + rankPoints_[v].selfCost))
                                  : this->cost(u, v);
                          if (cost < best || (cost == best && v < bestTarget_[u])) {
                            best = cost;
                            bestTarget_[u] = v;
                          }
                        }
                        bestCost_[u] = best;
                      }
                    });
}

bool Simplifier::valid(std::uint32_t from, std::uint32_t to) {
  // Neighbourhoods from the pass's incidence: complete for any vertex no collapse of this pass
  // has targeted (dead triangles skipped, moved corners updated). Stamps instead of sets.
  const std::uint32_t stamp = ++stampToken_;
  for (std::uint32_t t : around(to)) {
    if (!alive(t)) continue;
    for (std::uint32_t w : corners_[t]) nearTo_[w] = stamp;
  }
  std::uint32_t shared = 0, common = 0, fan = 0;
  for (std::uint32_t t : around(from)) {
    if (!alive(t)) continue;
    ++fan;
    shared += contains(t, to) ? 1u : 0u;
    for (std::uint32_t w : corners_[t]) {
      if (w == from || w == to || seen_[w] == stamp) continue;
      seen_[w] = stamp;
      common += nearTo_[w] == stamp ? 1u : 0u;
    }
  }
  if (shared == 0) return false;  // the edge is gone
  // Link condition: the common neighbours of the two ends are exactly the opposite corners of
  // the triangles on the edge; otherwise the collapse would create a non-manifold edge.
  if (common != shared) return false;
  const Vec3d target = position(to);
  const bool tetrahedron = fan == 3;
  for (std::uint32_t t : around(from)) {
    if (!alive(t) || contains(t, to)) continue;
    if (tetrahedron) {
      // Only a valence-3 vertex can pass the link condition and still recreate a triangle that
      // exists around `to` (the last collapse of a closed tetrahedron).
      std::uint32_t x = kNone, y = kNone;
      for (std::uint32_t w : corners_[t]) {
        if (w == from) continue;
        (x == kNone ? x : y) = w;
      }
      for (std::uint32_t s : around(to)) {
        if (alive(s) && contains(s, x) && contains(s, y)) return false;
      }
    }
    // No flip and no degenerate result.
    std::array<Vec3d, 3> before, after;
    for (std::size_t k = 0; k < 3; ++k) {
      before[k] = position(corners_[t][k]);
      after[k] = corners_[t][k] == from ? target : before[k];
    }
    const Vec3d n0 = cross(before[1] - before[0], before[2] - before[0]);
    const Vec3d n1 = cross(after[1] - after[0], after[2] - after[0]);
    // No flip, and no face turned by more than ~75 degrees either: near-flips make slivers
    // that stick out of the surface.
    const double d = dot(n0, n1), l0 = dot(n0, n0), l1 = dot(n1, n1);
    if (d <= 0 || l1 <= 0 || d * d <= 0.0625 * l0 * l1) return false;  // cos <= 0.25, without roots
  }
  return true;
}

std::uint32_t Simplifier::validTarget(std::uint32_t from, float bestCost) {
  const std::uint32_t best = bestTarget_[from];
  // A touched target has a new quadric and fan: `from` is dirty and re-ranked next pass.
  if (touched_[best] == pass_) return kNone;
  if (valid(from, best)) return best;
  // The best is blocked: the others in cost order, as long as they are not much dearer than
  // what this pass is collapsing anyway.
  std::array<std::pair<float, std::uint32_t>, 64> others;
  std::size_t count = 0;
  for (std::uint32_t t : around(from)) {
    if (!alive(t)) continue;
    for (std::uint32_t v : corners_[t]) {
      if (v == from || v == best || touched_[v] == pass_ || !allowed(from, v) ||
          count == others.size())
        continue;
      if (std::find_if(others.begin(), others.begin() + static_cast<std::ptrdiff_t>(count),
                       [&](const auto& o) { return o.second == v; }) !=
          others.begin() + static_cast<std::ptrdiff_t>(count)) {
        continue;
      }
      others[count++] = {cost(from, v), v};
    }
  }
  std::sort(others.begin(), others.begin() + static_cast<std::ptrdiff_t>(count));
  for (std::size_t i = 0; i < count; ++i) {
    if (others[i].first > passLimit_ && others[i].first > bestCost) break;
    if (valid(from, others[i].second)) return others[i].second;
  }
  return kNone;
}

void Simplifier::markChanged(std::uint32_t from, std::uint32_t to) {
  // Who must be re-ranked after `from` collapses into `to`. Half-edge collapses move no vertex
  // and only Q_to changes, growing, so around the two ends only costs to `to` change: up for
  // the old neighbours of `to`, new for those `from` hands over. A vertex whose best was one of
  // the ends is re-ranked in full; one that gains `to` compares that one cost; the rest keep
  // their best. Melax's cost looks at whole fans: everyone around is re-ranked.
  dirty_[to] = 1;
  const bool melax = options_.cost == CollapseCost::kMelax;
  const std::uint32_t stamp = ++stampToken_;
  for (std::uint32_t v : {from, to}) {
    for (std::uint32_t t : around(v)) {
      if (!alive(t)) continue;
      const bool gainsTo = v == from && !contains(t, to);
      for (std::uint32_t w : corners_[t]) {
        if (w == from || w == to || dirty_[w]) continue;
        if (melax || bestTarget_[w] == from || bestTarget_[w] == to) {
          dirty_[w] = 1;
        } else if (gainsTo && seen_[w] != stamp) {
          seen_[w] = stamp;
          newNeighbour_.emplace_back(w, to);
        }
      }
    }
  }
}

void Simplifier::rankNewNeighbours() {
  // The same result as a full re-rank of these vertices: their other costs did not change, and
  // ties go to the lower index as there.
  for (const auto& [w, to] : newNeighbour_) {
    if (dirty_[w] || removed_[w] || !allowed(w, to)) continue;
    const float cost = static_cast<float>(
        std::max(0.0, quadrics_[w].evaluate(position(to)) + rankPoints_[to].selfCost));
    if (cost < bestCost_[w] || (cost == bestCost_[w] && to < bestTarget_[w])) {
      bestCost_[w] = cost;
      bestTarget_[w] = to;
    }
  }
  newNeighbour_.clear();
}

void Simplifier::collapse(std::uint32_t from, std::uint32_t to) {
  const Vec3d moved = position(from);
  double distance = std::numeric_limits<double>::max();
  // Only the two ends are off limits for the rest of the pass: `to` is the one vertex whose fan
  // grows (its incidence list would be stale) and whose quadric changes. Every other vertex
  // keeps a complete incidence list (dead triangles are skipped, moved corners are updated in
  // place), so later checks in the pass still see the current mesh. Everyone whose cost inputs
  // change is re-ranked next pass.
  touched_[from] = touched_[to] = pass_;
  markChanged(from, to);
  for (std::uint32_t t : around(from)) {
    if (!alive(t)) continue;
    if (contains(t, to)) {
      corners_[t] = {kNone, kNone, kNone};
      removedTriangles_.push_back(t);
      continue;
    }
    for (std::uint32_t& c : corners_[t]) {
      if (c == from) c = to;
    }
    // How far the vanished vertex lies from the surface that now replaces it.
    distance = std::min(
        distance, pointTriangleDistanceSquared(moved, position(corners_[t][0]),
                                               position(corners_[t][1]), position(corners_[t][2])));
  }
  removed_[from] = 1;
  target_[from] = to;
  quadrics_[to] += quadrics_[from];
  rankPoints_[to].selfCost = quadrics_[to].evaluate(position(to));
  // Per-vertex error bound: what `from` already stood for, plus how far it just moved off the
  // surface (model units). The table keeps the running maximum so it is monotone.
  const double step = distance == std::numeric_limits<double>::max() ? 0.0 : std::sqrt(distance);
  vertexError_[to] = std::max(vertexError_[to], vertexError_[from] + step);
  maxError_ = std::max(maxError_, vertexError_[to]);
  collapsed_.push_back(from);
  trianglesAfter_.push_back(triangleCount_ - static_cast<std::uint32_t>(removedTriangles_.size()));
  errorAfter_.push_back(static_cast<float>(maxError_));
}

void Simplifier::collapseAll() {
  std::vector<std::pair<float, std::uint32_t>> ranked;
  while (true) {
    ++pass_;
    buildIncidence();
    rankCollapses();
    ranked.clear();
    for (std::uint32_t u : active_) {
      if (bestTarget_[u] != kNone) ranked.emplace_back(bestCost_[u], u);
    }
    if (ranked.empty()) break;
    // The cheapest share first, in cost order; if none of those can collapse, the rest before
    // giving up.
    const std::size_t share = std::max<std::size_t>(
        1, static_cast<std::size_t>(kPassShare * static_cast<double>(ranked.size())));
    std::nth_element(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(share - 1),
                     ranked.end());
    // Many small cost buckets, each walked in vertex order: neighbours in memory are neighbours
    // on the surface (fewer cache misses on big meshes), and the cost order barely changes. Only
    // the bucket boundaries need the cost order (pairs are unique, so the buckets hold exactly
    // what a full sort would put there).
    const std::size_t bucket = std::max<std::size_t>(1, share / kBuckets);
    partitionBuckets(ranked.begin(), 0, (share + bucket - 1) / bucket, bucket, share);
    for (std::size_t b = 0; b < share; b += bucket) {
      const auto first = ranked.begin() + static_cast<std::ptrdiff_t>(b);
      const auto last = ranked.begin() + static_cast<std::ptrdiff_t>(std::min(share, b + bucket));
      std::sort(first, last, [](const auto& x, const auto& y) { return x.second < y.second; });
    }
    const std::size_t before = collapsed_.size();
    for (std::size_t limit : {share, ranked.size()}) {
      if (limit == ranked.size() && limit > share)
        std::sort(ranked.begin() + static_cast<std::ptrdiff_t>(share), ranked.end());
      passLimit_ = ranked[limit - 1].first;
      for (std::size_t i = 0; i < limit; ++i) {
        const std::uint32_t from = ranked[i].second;
        if (touched_[from] == pass_ || removed_[from]) continue;
        const std::uint32_t to = validTarget(from, ranked[i].first);
        if (to != kNone) collapse(from, to);
      }
      if (collapsed_.size() > before) break;
    }
    if (collapsed_.size() == before) break;  // nothing can collapse any more
  }
}

ProgressiveMesh Simplifier::rearrange(std::span<const Vec3f> normals,
                                      std::span<const Rgba8> colors) const {
  ProgressiveMesh mesh;
  const auto collapses = static_cast<std::uint32_t>(collapsed_.size());
  mesh.q = vertexCount_ - collapses;
  // PermuteV: vertices that never collapse keep their order at the front; the k-th collapsed
  // vertex goes to p - 1 - k, so the first removed is last.
  mesh.permuteV.assign(vertexCount_, kNone);
  std::uint32_t next = 0;
  for (std::uint32_t v = 0; v < vertexCount_; ++v) {
    if (!removed_[v]) mesh.permuteV[v] = next++;
  }
  for (std::uint32_t k = 0; k < collapses; ++k) mesh.permuteV[collapsed_[k]] = vertexCount_ - 1 - k;
  // PermuteT: surviving triangles first, then the removed ones, latest removal first.
  mesh.permuteT.assign(triangleCount_, kNone);
  next = 0;
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    if (alive(t)) mesh.permuteT[t] = next++;
  }
  const auto removedCount = static_cast<std::uint32_t>(removedTriangles_.size());
  for (std::uint32_t r = 0; r < removedCount; ++r)
    mesh.permuteT[removedTriangles_[r]] = triangleCount_ - 1 - r;

  // Algorithm 1: ECol'[permuteV(i)] = permuteV(ecol(i)); V'[permuteV(i)] = V[i]; T'[permuteT(i)] =
  // T[i].
  mesh.positions.resize(vertexCount_);
  mesh.ecol.resize(vertexCount_);
  if (!normals.empty()) mesh.normals.resize(vertexCount_);
  if (!colors.empty()) mesh.colors.resize(vertexCount_);
  for (std::uint32_t v = 0; v < vertexCount_; ++v) {
    const std::uint32_t to = mesh.permuteV[v];
    mesh.positions[to] = positions_[v];
    if (!normals.empty()) mesh.normals[to] = normals[v];
    if (!colors.empty()) mesh.colors[to] = colors[v];
    mesh.ecol[to] = removed_[v] ? mesh.permuteV[target_[v]] : to;
    // The target always outlives the collapsed vertex, so it sits earlier: chains decrease.
    assert(!removed_[v] || mesh.ecol[to] < to);
  }
  mesh.triangles.resize(3 * std::size_t{triangleCount_});
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    for (std::size_t k = 0; k < 3; ++k)
      mesh.triangles[3 * std::size_t{mesh.permuteT[t]} + k] = mesh.permuteV[indices_[3 * t + k]];
  }
  // Map and error for every vertex count n in [q, p]: n = p - k after k collapses.
  mesh.map.resize(collapses + 1);
  mesh.error.resize(collapses + 1);
  mesh.map[collapses] = triangleCount_;
  mesh.error[collapses] = 0;
  for (std::uint32_t k = 0; k < collapses; ++k) {
    mesh.map[collapses - 1 - k] = trianglesAfter_[k];
    mesh.error[collapses - 1 - k] = errorAfter_[k];
  }
  return mesh;
}

}  // namespace

ProgressiveMesh buildProgressive(std::span<const Vec3f> positions,
                                 std::span<const std::uint32_t> indices,
                                 std::span<const Vec3f> normals, std::span<const Rgba8> colors,
                                 const ProgressiveOptions& options) {
  assert(indices.size() % 3 == 0);
  assert(normals.empty() || normals.size() == positions.size());
  assert(colors.empty() || colors.size() == positions.size());
  Simplifier simplifier(positions, indices, options);
  simplifier.classifyBoundary();
  simplifier.computeQuadrics();
  simplifier.collapseAll();
  return simplifier.rearrange(normals, colors);
}

}  // namespace lodforge
