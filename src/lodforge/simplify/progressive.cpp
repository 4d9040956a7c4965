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
  // Per vertex: quadric 80, incidence ~28, ranking 8, flags and stamps 6, error 8, the
  // rearranged output and permutation ~48. Per triangle: corners 12, flags and removal order 5,
  // rearranged output and permutation 16, Melax's face normals 24, the edge sort 24 (transient).
  return vertices * 200 + triangles * 84 + 4096;
}

namespace {

constexpr std::uint32_t kNone = ~0u;
// Each pass collapses at most this share of the ranked candidates (the cheapest ones): small
// enough that costs stay close to a global order, large enough that passes stay few. 0.2 keeps
// the distance to the original within ~1.2x of meshoptimizer's at 10 % and 1 % (bench_simplify)
// at about 0.4x its speed; 1.0 would be ~10 % faster and clearly worse in between.
constexpr double kPassShare = 0.2;
constexpr std::size_t kBuckets = 32;  // cost buckets per pass, each walked in vertex order

// Collapses happen in passes over flat arrays (as meshoptimizer does), not through one global
// priority queue: each pass ranks every vertex's cheapest valid-looking collapse, sorts them,
// and applies the cheapest quarter that do not touch one another, in cost order. Collapses in a
// pass never share a neighbourhood, so every validity check sees the current mesh, and the
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
  Vec3d position(std::uint32_t v) const { return points_[v]; }
  bool contains(std::uint32_t t, std::uint32_t v) const {
    return corners_[t][0] == v || corners_[t][1] == v || corners_[t][2] == v;
  }
  // The triangles around v as of the pass start; some may have died since (check alive_).
  std::span<const std::uint32_t> around(std::uint32_t v) const {
    return std::span(incident_).subspan(incidentStart_[v],
                                        incidentStart_[v + 1] - incidentStart_[v]);
  }
  bool allowed(std::uint32_t from, std::uint32_t to) const;
  void buildIncidence();
  void rankCollapses();
  float cost(std::uint32_t from, std::uint32_t to) const;
  bool valid(std::uint32_t from, std::uint32_t to);
  // The cheapest valid, untouched target of `from` (its ranked best first); kNone if none.
  std::uint32_t validTarget(std::uint32_t from, float bestCost);
  void collapse(std::uint32_t from, std::uint32_t to);

  std::span<const Vec3f> positions_;
  std::span<const std::uint32_t> indices_;
  ProgressiveOptions options_;
  std::uint32_t vertexCount_, triangleCount_;

  std::vector<Vec3d> points_;                          // positions in double, read often
  std::vector<std::array<std::uint32_t, 3>> corners_;  // current (re-formed) corners
  std::vector<std::uint8_t> alive_;                    // per triangle
  std::vector<std::uint8_t> locked_;                   // Q: boundary or non-manifold
  std::vector<std::uint8_t> removed_;                  // per vertex: collapsed already
  std::vector<Quadric> quadrics_;
  std::vector<double> selfCost_;     // Q_v(p_v): the quadric of a vertex at its own position
  std::vector<double> vertexError_;  // error carried by each live vertex
  std::vector<Vec3d> faceNormals_;   // per pass, for Melax's cost

  // Per pass: vertex -> live triangles (CSR), and each vertex's best collapse.
  std::vector<std::uint32_t> incidentStart_, incident_;
  std::vector<float> bestCost_;
  std::vector<std::uint32_t> bestTarget_;
  std::vector<std::uint8_t> dirty_;  // must be re-ranked next pass
  std::vector<std::uint32_t> live_, fill_;
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
  points_.resize(vertexCount_);
  for (std::uint32_t v = 0; v < vertexCount_; ++v) points_[v] = toDouble(positions_[v]);
  corners_.resize(triangleCount_);
  alive_.assign(triangleCount_, 1);
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
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * std::size_t{triangleCount_});
  for (const auto& c : corners_) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint64_t a = c[k], b = c[(k + 1) % 3];
      edges.push_back(std::min(a, b) << 32 | std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i != 2) {
      locked_[edges[i] >> 32] = 1;
      locked_[edges[i] & 0xFFFFFFFFu] = 1;
    }
    i = j;
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
  selfCost_.resize(vertexCount_);
  for (std::uint32_t v = 0; v < vertexCount_; ++v)
    selfCost_[v] = quadrics_[v].evaluate(position(v));
}

bool Simplifier::allowed(std::uint32_t from, std::uint32_t to) const {
  // Eq. 1: a boundary vertex never moves; an edge between two is never collapsed.
  if (locked_[from]) return false;
  if (options_.direction == CollapseDirection::kCheaper) return true;
  // Eq. 1 literally: the lower index moves unless it is a boundary vertex.
  return from < to || locked_[to];
}

void Simplifier::buildIncidence() {
  // Only the live triangles: the list shrinks pass after pass.
  if (live_.empty() && pass_ == 1) {
    live_.resize(triangleCount_);
    for (std::uint32_t t = 0; t < triangleCount_; ++t) live_[t] = t;
  } else {
    live_.erase(
        std::remove_if(live_.begin(), live_.end(), [&](std::uint32_t t) { return !alive_[t]; }),
        live_.end());
  }
  incidentStart_.assign(std::size_t{vertexCount_} + 1, 0);
  for (std::uint32_t t : live_) {
    for (std::uint32_t v : corners_[t]) ++incidentStart_[v + 1];
  }
  for (std::uint32_t v = 0; v < vertexCount_; ++v) incidentStart_[v + 1] += incidentStart_[v];
  incident_.resize(incidentStart_[vertexCount_]);
  fill_.assign(incidentStart_.begin(), incidentStart_.end() - 1);
  for (std::uint32_t t : live_) {
    for (std::uint32_t v : corners_[t]) incident_[fill_[v]++] = t;
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
    if (!alive_[t]) continue;
    double smallest = 1;
    for (std::uint32_t s : fan) {
      if (alive_[s] && contains(s, to))
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
                          const float cost = options_.cost == CollapseCost::kQuadric
                                                 ? static_cast<float>(std::max(
                                                       0.0, q.evaluate(position(v)) + selfCost_[v]))
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
    if (!alive_[t]) continue;
    for (std::uint32_t w : corners_[t]) nearTo_[w] = stamp;
  }
  std::uint32_t shared = 0, common = 0, fan = 0;
  for (std::uint32_t t : around(from)) {
    if (!alive_[t]) continue;
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
    if (!alive_[t] || contains(t, to)) continue;
    if (tetrahedron) {
      // Only a valence-3 vertex can pass the link condition and still recreate a triangle that
      // exists around `to` (the last collapse of a closed tetrahedron).
      std::uint32_t x = kNone, y = kNone;
      for (std::uint32_t w : corners_[t]) {
        if (w == from) continue;
        (x == kNone ? x : y) = w;
      }
      for (std::uint32_t s : around(to)) {
        if (alive_[s] && contains(s, x) && contains(s, y)) return false;
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
    if (!alive_[t]) continue;
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

void Simplifier::collapse(std::uint32_t from, std::uint32_t to) {
  const Vec3d moved = position(from);
  double distance = std::numeric_limits<double>::max();
  // Only the two ends are off limits for the rest of the pass: `to` is the one vertex whose fan
  // grows (its incidence list would be stale) and whose quadric changes. Every other vertex
  // keeps a complete incidence list (dead triangles are skipped, moved corners are updated in
  // place), so later checks in the pass still see the current mesh. Everyone whose cost inputs
  // change is re-ranked next pass.
  touched_[from] = touched_[to] = pass_;
  for (std::uint32_t v : {from, to}) {
    for (std::uint32_t t : around(v)) {
      if (!alive_[t]) continue;
      for (std::uint32_t w : corners_[t]) dirty_[w] = 1;
    }
  }
  for (std::uint32_t t : around(from)) {
    if (!alive_[t]) continue;
    if (contains(t, to)) {
      alive_[t] = 0;
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
  selfCost_[to] = quadrics_[to].evaluate(position(to));
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
    std::sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(share));
    // Within each of many small cost buckets, walk in vertex order: neighbours in memory are
    // neighbours on the surface (fewer cache misses on big meshes), and the cost order barely
    // changes.
    const std::size_t bucket = std::max<std::size_t>(1, share / kBuckets);
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
    if (alive_[t]) mesh.permuteT[t] = next++;
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
