#include "lodforge/simplify/progressive.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <utility>

#include "lodforge/core/distance.h"
#include "lodforge/core/quadric.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace lodforge {

std::uint32_t vertexCountForError(std::span<const float> error, std::uint32_t fewest,
                                  double allowed) {
  // Non-increasing: the entries over `allowed` come first, and the first one that fits answers.
  const auto fits = std::partition_point(error.begin(), error.end(),
                                         [allowed](float e) { return !(e <= allowed); });
  return fewest + static_cast<std::uint32_t>(fits - error.begin());
}

std::uint32_t ProgressiveMesh::vertexCountForError(float wanted) const {
  return lodforge::vertexCountForError(error, q, wanted);
}

std::uint64_t progressiveBuildBytes(std::uint64_t vertices, std::uint64_t triangles) {
  // Per vertex: state line 64, quadric 80, lists of live and active vertices and candidates ~16,
  // the rearranged output and permutation ~48, collapse target 4. Per triangle: corners 12,
  // fans 12 (up to twice that before a compaction), removal order 4, rearranged output and
  // permutation 16, live list 4, Melax's face normals 24.
  return vertices * 212 + triangles * 84 + 4096;
}

namespace {

constexpr std::uint32_t kNone = ~0u;
// The texture cost of a collapse whose wedges cannot be mapped (valid() refuses it): it ranks
// after every other.
constexpr double kRefused = 1e30;

// Twice the signed area of a triangle in texture space (positive counter-clockwise).
double signedUvArea(Vec2f a, Vec2f b, Vec2f c) {
  return (double(b.x) - a.x) * (double(c.y) - a.y) - (double(c.x) - a.x) * (double(b.y) - a.y);
}
// Each pass collapses at most this share of the ranked candidates (the cheapest ones): small
// enough that costs stay close to a global order, large enough that passes stay few. 0.2 keeps
// the distance to the original within ~1.2x of meshoptimizer's at 10 % and 1 % (bench_simplify)
// at about 0.4x its speed; 1.0 would be ~10 % faster and clearly worse in between.
constexpr double kPassShare = 0.2;
constexpr std::size_t kBuckets = 32;  // cost buckets per pass, each walked in vertex order

using Candidate = std::pair<float, std::uint32_t>;  // (cost, vertex)

// Sorts candidates by (cost, vertex) — for input in vertex order, which a stable LSD radix sort
// on the cost's bits keeps among equal costs. Costs are >= 0, so their bits order as integers.
void sortByCost(std::vector<Candidate>& items, std::vector<Candidate>& scratch) {
  if (items.size() < 4096) {
    std::sort(items.begin(), items.end());
    return;
  }
  constexpr std::uint32_t kBits = 11, kDigits = 3;
  constexpr std::uint32_t kMask = (1u << kBits) - 1;
  std::vector<std::array<std::uint32_t, 1u << kBits>> counts(kDigits);
  for (const Candidate& c : items) {
    const auto key = std::bit_cast<std::uint32_t>(c.first);
    for (std::uint32_t d = 0; d < kDigits; ++d) ++counts[d][(key >> (d * kBits)) & kMask];
  }
  scratch.resize(items.size());
  for (std::uint32_t d = 0; d < kDigits; ++d) {
    auto& count = counts[d];
    const auto key0 = std::bit_cast<std::uint32_t>(items[0].first);
    if (count[(key0 >> (d * kBits)) & kMask] == items.size()) continue;  // one digit value
    std::uint32_t sum = 0;
    for (std::uint32_t& c : count) sum += std::exchange(c, sum);
    for (const Candidate& c : items)
      scratch[count[(std::bit_cast<std::uint32_t>(c.first) >> (d * kBits)) & kMask]++] = c;
    items.swap(scratch);
  }
}

// Everything a collapse reads or writes about one vertex, in one cache line: a collapse visits
// a dozen vertices spread over the mesh, and separate arrays cost a miss per array per vertex.
// The position stays float as given (widened exactly to double where used).
struct alignas(64) VertexState {
  float x = 0, y = 0, z = 0;
  std::uint32_t incidentStart = 0, incidentCount = 0;  // this pass's fan in incident_
  std::uint32_t bestTarget = ~0u;                      // cheapest collapse as ranked
  float bestCost = 0;
  std::uint32_t touched = 0;                   // pass that last collapsed into or out of it
  std::uint32_t nearStamp = 0, seenStamp = 0;  // scratch marks for valid()
  double selfCost = 0;                         // Q_v(p_v), for (Q_u + Q_v)(p_v)
  double error = 0;                            // distance carried by this live vertex
  std::uint8_t locked = 0;                     // Q: boundary or non-manifold
  std::uint8_t removed = 0;                    // collapsed already
  std::uint8_t dirty = 1;                      // must be re-ranked next pass
  std::uint8_t gains = 0;                      // valid(): on a triangle around `from` without `to`
  std::uint8_t boundary = 0;  // collapseBorders: on two boundary edges, may move along them
};
static_assert(sizeof(VertexState) == 64);

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
        triangleCount_(static_cast<std::uint32_t>(indices.size() / 3)),
        minNormalCos2_(options.minNormalCos * options.minNormalCos) {
    assert(options.locked.empty() || options.locked.size() == positions.size());
    assert(options.wedges.empty() || options.wedges.size() == indices.size());
  }

  void classifyBoundary();
  void computeQuadrics();
  void addBoundaryPlanes();
  void addSeamPlanes();
  void addEdgePlane(std::uint32_t a, std::uint32_t b, Vec3d faceNormal);
  void computeUvQuadrics();
  void collapseAll();
  ProgressiveMesh rearrange(std::span<const Vec3f> normals, std::span<const Rgba8> colors) const;
  ProgressiveMesh rearrangeWedges(std::span<const Vec3f> normals,
                                  std::span<const Rgba8> colors) const;
  void wedgeLevels(std::span<const std::uint32_t> groupStart, ProgressiveMesh& mesh) const;
  SimplifiedMesh current() const;
  std::vector<std::uint32_t> triangleOrder() const;

 private:
  // The neighbours of a collapse's two ends (each once, the ends left out), as valid() found
  // them: whom markChanged() re-ranks if the collapse goes ahead. They live in ringFrom_ and
  // ringTo_ until the next valid().
  struct Rings {
    std::span<const std::uint32_t> from, to;
  };
  // A collapse target with the rings of its edge; vertex kNone: none.
  struct Target {
    std::uint32_t vertex = kNone;
    Rings rings;
  };

  Vec3d position(std::uint32_t v) const {
    const VertexState& s = vertex_[v];
    return {s.x, s.y, s.z};
  }
  // The dead mark shares the cache line the corners are read from anyway.
  bool alive(std::uint32_t t) const { return corners_[t][0] != kNone; }
  // The corners of t other than v, which t holds (branch-free: where v sits is random).
  std::array<std::uint32_t, 2> otherCorners(std::uint32_t t, std::uint32_t v) const {
    const auto& c = corners_[t];
    const std::uint32_t k = (c[1] == v) + 2u * (c[2] == v);
    return {c[k == 2 ? 0 : k + 1], c[k == 0 ? 2 : k - 1]};
  }
  bool contains(std::uint32_t t, std::uint32_t v) const {
    // Bitwise, not short-circuit: which corner matches is unpredictable.
    const auto& c = corners_[t];
    return ((c[0] == v) + (c[1] == v) + (c[2] == v)) != 0;
  }
  // The triangles around v in increasing order; some may have died since (check alive()).
  std::span<const std::uint32_t> around(std::uint32_t v) const {
    return std::span(incident_).subspan(vertex_[v].incidentStart, vertex_[v].incidentCount);
  }
  bool allowed(std::uint32_t from, std::uint32_t to) const;
  bool textured() const { return !wedgeCorners_.empty(); }
  std::uint32_t wedgeAt(std::uint32_t t, std::uint32_t v) const {
    const auto& c = corners_[t];
    return wedgeCorners_[t][(c[1] == v) + 2u * (c[2] == v)];
  }
  bool isSeam(std::uint32_t t, std::uint32_t a, std::uint32_t b) const;
  // Where each wedge of a collapse's `from` goes (from's wedge, to's wedge); a vertex has a few.
  struct WedgeMap {
    std::array<std::pair<std::uint32_t, std::uint32_t>, 16> items;
    std::size_t count = 0;
    std::span<const std::pair<std::uint32_t, std::uint32_t>> pairs() const {
      return std::span(items).first(count);
    }
    std::uint32_t find(std::uint32_t wedge) const {
      for (const auto& [wf, wt] : pairs())
        if (wf == wedge) return wt;
      return kNone;
    }
  };
  bool mapWedges(std::uint32_t from, std::uint32_t to, WedgeMap& map) const;
  double uvCost(std::uint32_t from, std::uint32_t to) const;
  std::uint32_t onlyWedge(std::uint32_t v) const;
  bool keepsTextureOrientation(std::uint32_t from, std::uint32_t to) const;
  void moveWedges(std::uint32_t from, std::uint32_t to);
  void buildIncidence();
  void mergeFans(std::uint32_t from, std::uint32_t to);
  void updateFaceNormals();
  void rankCollapses();
  void rankVertex(std::uint32_t u);
  float cost(std::uint32_t from, std::uint32_t to) const;
  std::optional<Rings> valid(std::uint32_t from, std::uint32_t to);
  std::uint32_t removedTriangleCount() const {
    return static_cast<std::uint32_t>(removedTriangles_.size());
  }
  // The cheapest valid, untouched target of `from` (its ranked best first); kNone if none.
  Target validTarget(std::uint32_t from, float bestCost);
  double stepDistance(std::uint32_t from, std::uint32_t to) const;
  // `step`: stepDistance(from, to), measured before the fan changes.
  void collapse(std::uint32_t from, const Target& to, double step);
  void markChanged(std::uint32_t from, const Target& to);
  void rankNewNeighbours();

  std::span<const Vec3f> positions_;
  std::span<const std::uint32_t> indices_;
  ProgressiveOptions options_;
  std::uint32_t vertexCount_, triangleCount_;
  double minNormalCos2_;  // squared: compared without roots

  std::vector<VertexState> vertex_;
  std::vector<std::array<std::uint32_t, 3>> corners_;  // current (re-formed); dead: all kNone
  std::vector<Quadric> quadrics_;
  std::vector<Vec3d> faceNormals_;  // per pass, for Melax's cost

  // Vertex -> triangles (ranges in VertexState); a grown fan is appended, stale lists stay
  // behind until buildIncidence() compacts.
  std::vector<std::uint32_t> incident_;
  std::vector<std::uint32_t> liveVertices_;  // not collapsed yet
  // (vertex, new neighbour): the one new cost to compare next pass.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> newNeighbour_;
  std::size_t newNeighbourCount_ = 0;
  std::vector<std::uint32_t> ringFrom_, ringTo_;  // storage of the Rings valid() returns
  std::vector<std::uint32_t> liveTriangles_;
  std::vector<std::uint32_t> active_;  // vertices that may still collapse
  std::uint32_t stampToken_ = 0;
  std::uint32_t pass_ = 0;
  float passLimit_ = 0;  // the dearest cost this pass may collapse

  // The record of collapses, in order.
  std::vector<std::uint32_t> collapsed_;         // vertex removed by collapse k
  std::vector<std::uint32_t> target_;            // per vertex: what it collapsed into
  std::vector<std::uint32_t> removedTriangles_;  // in order of removal
  std::vector<std::uint32_t> trianglesAfter_;    // triangle count after collapse k
  std::vector<float> errorAfter_;                // monotone error after collapse k
  double maxError_ = 0;
  std::vector<std::uint8_t> border_;  // per vertex: on a boundary or non-manifold edge

  // Textured meshes: the wedge of each corner (kept with corners_), each wedge's texture error
  // quadric and its value at the wedge itself, and the wedge map of the last valid() collapse.
  std::vector<std::array<std::uint32_t, 3>> wedgeCorners_;
  std::vector<UvQuadric> uvQuadrics_;
  std::vector<double> uvSelfCost_;
  WedgeMap wedgeMap_;
  std::vector<std::uint32_t> wedgeTarget_;  // per wedge: the wedge it went to (kNone: none yet)
};

void Simplifier::classifyBoundary() {
  vertex_.assign(vertexCount_, VertexState{});
  for (std::uint32_t v = 0; v < vertexCount_; ++v) {
    vertex_[v].x = positions_[v].x;
    vertex_[v].y = positions_[v].y;
    vertex_[v].z = positions_[v].z;
  }
  corners_.resize(triangleCount_);
  target_.assign(vertexCount_, kNone);
  if (!options_.wedges.empty()) {
    wedgeCorners_.resize(triangleCount_);
    for (std::uint32_t t = 0; t < triangleCount_; ++t)
      for (std::size_t k = 0; k < 3; ++k) wedgeCorners_[t][k] = options_.wedges[3 * t + k];
  }
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
  border_.assign(vertexCount_, 0);
  for (std::uint32_t u = 0; u < vertexCount_; ++u) {
    const auto fan = around(u);
    for (std::uint32_t t : fan) {
      for (std::uint32_t w : otherCorners(t, u)) edgeCount[w] = 0;
    }
    for (std::uint32_t t : fan) {
      for (std::uint32_t w : otherCorners(t, u)) ++edgeCount[w];
    }
    bool locked = false;
    std::uint32_t boundaryEdges = 0, nonManifold = 0;
    for (std::uint32_t t : fan) {
      for (std::uint32_t w : otherCorners(t, u)) {
        locked |= edgeCount[w] != 2;
        boundaryEdges += edgeCount[w] == 1;
        nonManifold += edgeCount[w] > 2;
      }
    }
    border_[u] = locked ? 1 : 0;
    if (options_.collapseBorders && locked && nonManifold == 0 && boundaryEdges == 2) {
      locked = false;  // a plain rim vertex: it may slide along its rim
      vertex_[u].boundary = 1;
    }
    vertex_[u].locked = locked || (!options_.locked.empty() && options_.locked[u] != 0);
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
  if (options_.collapseBorders) addBoundaryPlanes();
  if (textured()) {
    addSeamPlanes();
    computeUvQuadrics();
  }
  for (std::uint32_t v = 0; v < vertexCount_; ++v)
    vertex_[v].selfCost = quadrics_[v].evaluate(position(v));
}

void Simplifier::addEdgePlane(std::uint32_t a, std::uint32_t b, Vec3d faceNormal) {
  // The plane through edge a-b perpendicular to its face, weighted by the edge's squared length.
  const Vec3d edge = position(b) - position(a);
  const Vec3d across = cross(edge, faceNormal);
  const double span = length(across);
  if (span <= 0) return;
  const Quadric plane = Quadric::fromPlane(across / span, position(a), dot(edge, edge));
  quadrics_[a] += plane;
  quadrics_[b] += plane;
}

bool Simplifier::isSeam(std::uint32_t t, std::uint32_t a, std::uint32_t b) const {
  // Edge a-b of t is a seam where the triangle across it has other wedges at either end.
  for (std::uint32_t s : around(a)) {
    if (s == t || !alive(s) || !contains(s, b)) continue;
    if (wedgeAt(s, a) != wedgeAt(t, a) || wedgeAt(s, b) != wedgeAt(t, b)) return true;
  }
  return false;
}

void Simplifier::addSeamPlanes() {
  // As for a rim (addBoundaryPlanes): a plane through each seam edge, perpendicular to each face
  // on it, weighted by the edge's squared length, so a seam that slides keeps its course.
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    const auto& c = corners_[t];
    const Vec3d n = cross(position(c[1]) - position(c[0]), position(c[2]) - position(c[0]));
    const double twiceArea = length(n);
    if (twiceArea <= 0) continue;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = c[k], b = c[(k + 1) % 3];
      if (isSeam(t, a, b)) addEdgePlane(a, b, n / twiceArea);
    }
  }
}

void Simplifier::computeUvQuadrics() {
  // Texture coordinates count in model units: scaled by the mesh's model-to-texture ratio (the
  // square root of its area over its texture area), so a texture error weighs like a distance.
  const std::span<const Vec2f> uv = options_.wedgeUvs;
  std::uint32_t wedgeCount = 0;
  for (std::uint32_t w : options_.wedges) wedgeCount = std::max(wedgeCount, w + 1);
  assert(uv.size() >= wedgeCount);
  double area = 0, uvArea = 0;
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    const auto& c = corners_[t];
    const auto& w = wedgeCorners_[t];
    area += 0.5 * length(cross(position(c[1]) - position(c[0]), position(c[2]) - position(c[0])));
    uvArea += 0.5 * std::abs(signedUvArea(uv[w[0]], uv[w[1]], uv[w[2]]));
  }
  const double scale2 = uvArea > 0 ? area / uvArea : 0.0;
  uvQuadrics_.assign(wedgeCount, UvQuadric{});
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    const auto& c = corners_[t];
    const auto& w = wedgeCorners_[t];
    const Vec3d a = position(c[0]), b = position(c[1]), d = position(c[2]);
    const double weight = 0.5 * length(cross(b - a, d - a)) * scale2;
    const UvQuadric q = UvQuadric::fromTriangle(a, b, d, uv[w[0]], uv[w[1]], uv[w[2]], weight);
    for (std::uint32_t wedge : w) uvQuadrics_[wedge] += q;
  }
  uvSelfCost_.assign(wedgeCount, 0.0);
  wedgeTarget_.assign(wedgeCount, kNone);
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t wedge = wedgeCorners_[t][k];
      uvSelfCost_[wedge] = uvQuadrics_[wedge].evaluate(position(corners_[t][k]), uv[wedge]);
    }
  }
}

bool Simplifier::mapWedges(std::uint32_t from, std::uint32_t to, WedgeMap& map) const {
  // Each wedge of `from` goes to the wedge `to` has on the triangles of their edge (the ones that
  // die): one target per wedge, and every wedge of `from` still in use must have one, or a
  // triangle would take coordinates from another chart.
  map.count = 0;
  for (std::uint32_t t : around(from)) {
    if (!alive(t) || !contains(t, to)) continue;
    const std::uint32_t wf = wedgeAt(t, from), wt = wedgeAt(t, to);
    const std::uint32_t known = map.find(wf);
    if (known == kNone) {
      if (map.count == map.items.size()) return false;
      map.items[map.count++] = {wf, wt};
    } else if (known != wt) {
      return false;
    }
  }
  for (std::uint32_t t : around(from)) {
    if (alive(t) && !contains(t, to) && map.find(wedgeAt(t, from)) == kNone) return false;
  }
  return map.count > 0;
}

std::uint32_t Simplifier::onlyWedge(std::uint32_t v) const {
  // The wedge of v if its live triangles all share one, kNone if they have several.
  std::uint32_t wedge = kNone;
  for (std::uint32_t t : around(v)) {
    if (!alive(t)) continue;
    const std::uint32_t w = wedgeAt(t, v);
    if (wedge != kNone && w != wedge) return kNone;
    wedge = w;
  }
  return wedge;
}

double Simplifier::uvCost(std::uint32_t from, std::uint32_t to) const {
  // Each wedge's texture error at its target's coordinates, (Q_w + Q_w')(p_to, uv_w').
  WedgeMap map;
  if (!mapWedges(from, to, map)) return kRefused;  // valid() refuses it: never the cheapest
  const Vec3d p = position(to);
  double sum = 0;
  for (const auto& [wf, wt] : map.pairs())
    sum += uvQuadrics_[wf].evaluate(p, options_.wedgeUvs[wt]) + uvSelfCost_[wt];
  return std::max(0.0, sum);
}

bool Simplifier::keepsTextureOrientation(std::uint32_t from, std::uint32_t to) const {
  // No triangle that stays may turn over (or collapse) in texture space: it would fold its chart.
  const std::span<const Vec2f> uv = options_.wedgeUvs;
  for (std::uint32_t t : around(from)) {
    if (!alive(t) || contains(t, to)) continue;
    const auto& w = wedgeCorners_[t];
    const std::uint32_t k = (corners_[t][1] == from) + 2u * (corners_[t][2] == from);
    std::array<std::uint32_t, 3> after = w;
    after[k] = wedgeMap_.find(w[k]);
    const double before = signedUvArea(uv[w[0]], uv[w[1]], uv[w[2]]);
    const double now = signedUvArea(uv[after[0]], uv[after[1]], uv[after[2]]);
    if (before * now < 0 || (before != 0 && now == 0)) return false;
  }
  return true;
}

void Simplifier::moveWedges(std::uint32_t from, std::uint32_t to) {
  // After valid(from, to): the corners `from` hands over take their mapped wedges, and each
  // target wedge takes on its source's texture error.
  for (std::uint32_t t : around(from)) {
    if (!alive(t) || contains(t, to)) continue;
    const std::uint32_t k = (corners_[t][1] == from) + 2u * (corners_[t][2] == from);
    wedgeCorners_[t][k] = wedgeMap_.find(wedgeCorners_[t][k]);
  }
  const Vec3d p = position(to);
  for (const auto& [wf, wt] : wedgeMap_.pairs()) {
    wedgeTarget_[wf] = wt;
    uvQuadrics_[wt] += uvQuadrics_[wf];
    uvSelfCost_[wt] = uvQuadrics_[wt].evaluate(p, options_.wedgeUvs[wt]);
  }
}

void Simplifier::addBoundaryPlanes() {
  // A plane through each boundary edge, perpendicular to its face, weighted by the edge's
  // squared length (Garland & Heckbert's boundary constraint): moving a rim vertex off its rim
  // costs as much as lifting a face. Only faces with a corner on the boundary are looked at.
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    const auto& c = corners_[t];
    if (border_[c[0]] + border_[c[1]] + border_[c[2]] < 2) continue;
    const Vec3d n = cross(position(c[1]) - position(c[0]), position(c[2]) - position(c[0]));
    const double twiceArea = length(n);
    if (twiceArea <= 0) continue;
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = c[k], b = c[(k + 1) % 3];
      if (border_[a] == 0 || border_[b] == 0) continue;
      std::uint32_t onEdge = 0;
      for (std::uint32_t s : around(a)) onEdge += contains(s, b) ? 1u : 0u;
      if (onEdge == 1) addEdgePlane(a, b, n / twiceArea);
    }
  }
}

bool Simplifier::allowed(std::uint32_t from, std::uint32_t to) const {
  // Eq. 1: a boundary vertex never moves; an edge between two is never collapsed.
  if (vertex_[from].locked) return false;
  if (options_.direction == CollapseDirection::kCheaper) return true;
  // Eq. 1 literally: the lower index moves unless it is a boundary vertex.
  return from < to || vertex_[to].locked;
}

void Simplifier::buildIncidence() {
  // Only the live triangles and vertices. Between rebuilds, collapse() appends the one fan that
  // grows, so the array fills with stale lists; a rebuild compacts it.
  if (liveTriangles_.empty()) {
    liveTriangles_.resize(triangleCount_);
    for (std::uint32_t t = 0; t < triangleCount_; ++t) liveTriangles_[t] = t;
    liveVertices_.resize(vertexCount_);
    for (std::uint32_t v = 0; v < vertexCount_; ++v) liveVertices_[v] = v;
  } else {
    std::erase_if(liveTriangles_, [&](std::uint32_t t) { return !alive(t); });
    std::erase_if(liveVertices_, [&](std::uint32_t v) { return vertex_[v].removed != 0; });
  }
  for (std::uint32_t v : liveVertices_) vertex_[v].incidentCount = 0;
  for (std::uint32_t t : liveTriangles_) {
    for (std::uint32_t v : corners_[t]) ++vertex_[v].incidentCount;
  }
  std::uint32_t end = 0;
  for (std::uint32_t v : liveVertices_) {
    end += vertex_[v].incidentCount;
    vertex_[v].incidentStart = end;  // filled backwards below, so it ends at the start
  }
  incident_.resize(end);
  // Backwards, so that each fan lists its triangles in increasing order.
  for (auto t = liveTriangles_.rbegin(); t != liveTriangles_.rend(); ++t) {
    for (std::uint32_t v : corners_[*t]) incident_[--vertex_[v].incidentStart] = *t;
  }
}

void Simplifier::mergeFans(std::uint32_t from, std::uint32_t to) {
  // After the collapse, the fan of `to` is its own live triangles and those `from` handed over
  // (the two sets are disjoint: a triangle with both ends died). Both lists are in increasing
  // order and so is the merge, as a rebuild would list them.
  const std::size_t start = incident_.size();
  VertexState& target = vertex_[to];
  const VertexState& source = vertex_[from];
  incident_.resize(start + target.incidentCount + source.incidentCount);
  const std::uint32_t* a = incident_.data() + target.incidentStart;
  const std::uint32_t* const aEnd = a + target.incidentCount;
  const std::uint32_t* b = incident_.data() + source.incidentStart;
  const std::uint32_t* const bEnd = b + source.incidentCount;
  std::uint32_t* const first = incident_.data() + start;
  std::uint32_t* out = first;
  while (a != aEnd || b != bEnd) {
    const std::uint32_t t = b == bEnd || (a != aEnd && *a < *b) ? *a++ : *b++;
    *out = t;
    out += alive(t);
  }
  target.incidentStart = static_cast<std::uint32_t>(start);
  target.incidentCount = static_cast<std::uint32_t>(out - first);
  incident_.resize(start + target.incidentCount);
}

void Simplifier::updateFaceNormals() {
  std::erase_if(liveTriangles_, [&](std::uint32_t t) { return !alive(t); });
  faceNormals_.resize(triangleCount_);
  tbb::parallel_for(std::size_t{0}, liveTriangles_.size(), [&](std::size_t i) {
    const std::uint32_t t = liveTriangles_[i];
    const Vec3d a = position(corners_[t][0]), b = position(corners_[t][1]),
                c = position(corners_[t][2]);
    faceNormals_[t] = normalizeOr(cross(b - a, c - a), Vec3d{});
  });
}

float Simplifier::cost(std::uint32_t from, std::uint32_t to) const {
  if (options_.cost == CollapseCost::kQuadric) {
    const Quadric q = quadrics_[from] + quadrics_[to];
    const double uv = textured() ? uvCost(from, to) : 0.0;
    return static_cast<float>(std::max(0.0, q.evaluate(position(to))) + uv);
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
  // Only vertices whose cost inputs changed last pass (Melax's cost looks at whole fans, so
  // it re-ranks everything). In vertex order: neighbours in memory are neighbours on the surface.
  if (pass_ == 1) {
    for (std::uint32_t u = 0; u < vertexCount_; ++u) {
      if (!vertex_[u].locked) active_.push_back(u);
    }
  }
  const bool all = options_.cost == CollapseCost::kMelax;
  rankNewNeighbours();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, active_.size(), 512),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t a = range.begin(); a < range.end(); ++a) {
                        const VertexState& su = vertex_[active_[a]];
                        if (!su.removed && (all || su.dirty)) rankVertex(active_[a]);
                      }
                    });
}

void Simplifier::rankVertex(std::uint32_t u) {
  // Each neighbour once: the corner after u in each triangle of its fan (an interior vertex of a
  // consistently oriented manifold sees every neighbour exactly so). u is active, so not locked.
  // Branch-free where the data decides: u's corner and the running minimum.
  const bool paper = options_.direction != CollapseDirection::kCheaper;
  const bool quadric = options_.cost == CollapseCost::kQuadric;
  const Quadric& q = quadrics_[u];
  float best = std::numeric_limits<float>::max();
  std::uint32_t bestTarget = kNone;
  const auto consider = [&](std::uint32_t v, float cost) {
    const bool better = (cost < best) | ((cost == best) & (v < bestTarget));
    best = better ? cost : best;
    bestTarget = better ? v : bestTarget;
  };
  // (Q_u + Q_v)(p_v) = Q_u(p_v) + Q_v(p_v); the second term is cached per vertex. Quadric costs
  // go two neighbours at a time (the minimum does not depend on the order).
  const auto quadricCost = [&](double atV, std::uint32_t v) {
    return static_cast<float>(std::max(0.0, atV + vertex_[v].selfCost));
  };
  // Textured: most vertices are inside one chart, with one wedge, whose texture cost to v needs
  // only v's wedge on this triangle (uvCost's walk of the fan, for the others).
  const std::uint32_t soleWedge = textured() ? onlyWedge(u) : kNone;
  std::uint32_t pending = kNone;
  for (std::uint32_t t : around(u)) {
    const auto& c = corners_[t];
    if (c[0] == kNone) continue;  // died since the fan was listed
    const std::uint32_t v = otherCorners(t, u)[0];
    if (paper && !allowed(u, v)) continue;
    if (quadric && soleWedge != kNone) {
      const std::uint32_t wv = wedgeAt(t, v);
      const double uv =
          uvQuadrics_[soleWedge].evaluate(position(v), options_.wedgeUvs[wv]) + uvSelfCost_[wv];
      consider(v, static_cast<float>(std::max(0.0, q.evaluate(position(v)) + vertex_[v].selfCost) +
                                     std::max(0.0, uv)));
    } else if (!quadric || textured()) {
      consider(v, this->cost(u, v));
    } else if (pending == kNone) {
      pending = v;
    } else {
      double atPending = 0, atV = 0;
      q.evaluate(position(pending), position(v), atPending, atV);
      consider(pending, quadricCost(atPending, pending));
      consider(v, quadricCost(atV, v));
      pending = kNone;
    }
  }
  if (pending != kNone) consider(pending, quadricCost(q.evaluate(position(pending)), pending));
  VertexState& su = vertex_[u];
  su.dirty = 0;
  su.bestTarget = bestTarget;
  su.bestCost = best;
}

std::optional<Simplifier::Rings> Simplifier::valid(std::uint32_t from, std::uint32_t to) {
  // Neighbourhoods from the pass's incidence: complete for any vertex no collapse of this pass
  // has targeted (dead triangles skipped, moved corners updated). Stamps instead of sets.
  // Both rings are returned (each vertex once, the ends left out): if the collapse goes ahead,
  // markChanged() walks them instead of the fans. Branch-free: which corner is new is random.
  const std::uint32_t stamp = ++stampToken_;
  const auto toFan = around(to), fromFan = around(from);
  if (ringTo_.size() < 3 * toFan.size()) ringTo_.resize(6 * toFan.size());
  if (ringFrom_.size() < 3 * fromFan.size()) ringFrom_.resize(6 * fromFan.size());
  // Every triangle of a fan holds its centre once, so only the other two corners are walked.
  std::size_t ringTo = 0, ringFrom = 0;
  for (std::uint32_t t : toFan) {
    if (!alive(t)) continue;
    for (std::uint32_t w : otherCorners(t, to)) {
      VertexState& sw = vertex_[w];
      ringTo_[ringTo] = w;
      ringTo += (w != from) & (sw.nearStamp != stamp);
      sw.nearStamp = stamp;
    }
  }
  std::uint32_t shared = 0, common = 0, fan = 0;
  for (std::uint32_t t : fromFan) {
    if (!alive(t)) continue;
    ++fan;
    const auto others = otherCorners(t, from);
    const bool onEdge = ((others[0] == to) + (others[1] == to)) != 0;
    shared += onEdge;
    for (std::uint32_t w : others) {
      // Marking `to` as seen is harmless (stamps are per call).
      VertexState& sw = vertex_[w];
      const bool fresh = (w != to) & (sw.seenStamp != stamp);
      common += fresh & (sw.nearStamp == stamp);
      sw.gains = static_cast<std::uint8_t>((fresh ? 0 : sw.gains) | !onEdge);
      sw.seenStamp = stamp;
      ringFrom_[ringFrom] = w;
      ringFrom += fresh;
    }
  }
  if (shared == 0) return std::nullopt;  // the edge is gone
  // Link condition: the common neighbours of the two ends are exactly the opposite corners of
  // the triangles on the edge; otherwise the collapse would create a non-manifold edge.
  if (common != shared) return std::nullopt;
  // A rim vertex moves only along its rim: over a boundary edge (one triangle), into the next.
  if (vertex_[from].boundary != 0 && shared != 1) return std::nullopt;
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
        if (alive(s) && contains(s, x) && contains(s, y)) return std::nullopt;
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
    if (d <= 0 || l1 <= 0 || d * d <= minNormalCos2_ * l0 * l1)
      return std::nullopt;  // without roots
  }
  if (textured() && !(mapWedges(from, to, wedgeMap_) && keepsTextureOrientation(from, to)))
    return std::nullopt;
  return Rings{std::span(ringFrom_).first(ringFrom), std::span(ringTo_).first(ringTo)};
}

Simplifier::Target Simplifier::validTarget(std::uint32_t from, float bestCost) {
  const std::uint32_t best = vertex_[from].bestTarget;
  // A touched target has a new quadric and fan: `from` is dirty and re-ranked next pass.
  if (vertex_[best].touched == pass_) return {};
  if (std::optional<Rings> rings = valid(from, best)) return {best, *rings};
  // The best is blocked: the others in cost order, as long as they are not much dearer than
  // what this pass is collapsing anyway.
  std::array<std::pair<float, std::uint32_t>, 64> others;
  std::size_t count = 0;
  for (std::uint32_t t : around(from)) {
    if (!alive(t)) continue;
    for (std::uint32_t v : corners_[t]) {
      if (v == from || v == best || vertex_[v].touched == pass_ || !allowed(from, v) ||
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
    if (std::optional<Rings> rings = valid(from, others[i].second))
      return {others[i].second, *rings};
  }
  return {};
}

void Simplifier::markChanged(std::uint32_t from, const Target& target) {
  const std::uint32_t to = target.vertex;
  // Who must be re-ranked after `from` collapses into `to`. Half-edge collapses move no vertex
  // and only Q_to changes, growing, so around the two ends only costs to `to` change: up for
  // the old neighbours of `to`, new for those `from` hands over. A vertex whose best was one of
  // the ends is re-ranked in full; one that gains `to` compares that one cost; the rest keep
  // their best. Melax's cost looks at whole fans: everyone around is re-ranked.
  const bool melax = options_.cost == CollapseCost::kMelax;
  vertex_[to].dirty = 1;
  // The rings valid() collected: from's ring first (who gains `to`), then to's.
  const Rings& rings = target.rings;
  if (newNeighbour_.size() < newNeighbourCount_ + rings.from.size())
    newNeighbour_.resize(2 * (newNeighbourCount_ + rings.from.size()));
  for (std::uint32_t w : rings.from) {
    VertexState& sw = vertex_[w];
    const bool other = !sw.dirty;
    const bool redo = other & (melax | (sw.bestTarget == from) | (sw.bestTarget == to));
    sw.dirty = static_cast<std::uint8_t>(sw.dirty | redo);
    newNeighbour_[newNeighbourCount_] = {w, to};
    newNeighbourCount_ += other & !redo & (sw.gains != 0);
  }
  for (std::uint32_t w : rings.to) {
    VertexState& sw = vertex_[w];
    const bool redo = (sw.dirty == 0) & (melax | (sw.bestTarget == from) | (sw.bestTarget == to));
    sw.dirty = static_cast<std::uint8_t>(sw.dirty | redo);
  }
}

void Simplifier::rankNewNeighbours() {
  // The same result as a full re-rank of these vertices: their other costs did not change, and
  // ties go to the lower index as there.
  for (const auto& [w, to] : std::span(newNeighbour_).first(newNeighbourCount_)) {
    if (vertex_[w].dirty || vertex_[w].removed || !allowed(w, to)) continue;
    const float cost = static_cast<float>(
        std::max(0.0, quadrics_[w].evaluate(position(to)) + vertex_[to].selfCost) +
        (textured() ? uvCost(w, to) : 0.0));
    if (cost < vertex_[w].bestCost || (cost == vertex_[w].bestCost && to < vertex_[w].bestTarget)) {
      vertex_[w].bestCost = cost;
      vertex_[w].bestTarget = to;
    }
  }
  newNeighbourCount_ = 0;
}

// How far `from` lies from the fan that replaces it once it collapses into `to` (model units):
// what its collapse adds to the error it already stands for.
double Simplifier::stepDistance(std::uint32_t from, std::uint32_t to) const {
  const Vec3d moved = position(from);
  double distance = std::numeric_limits<double>::max();
  for (std::uint32_t t : around(from)) {
    if (!alive(t) || contains(t, to)) continue;
    std::array<Vec3d, 3> p;
    for (std::size_t k = 0; k < 3; ++k)
      p[k] = position(corners_[t][k] == from ? to : corners_[t][k]);
    distance = std::min(distance, pointTriangleDistanceSquared(moved, p[0], p[1], p[2]));
  }
  return distance == std::numeric_limits<double>::max() ? 0.0 : std::sqrt(distance);
}

void Simplifier::collapse(std::uint32_t from, const Target& target, double step) {
  const std::uint32_t to = target.vertex;
  // Only the two ends are off limits for the rest of the pass: `to` is the one vertex whose fan
  // grows (merged below) and whose quadric changes, so its ranked costs are stale. Every other
  // vertex keeps a complete fan (dead triangles are skipped, moved corners are updated in
  // place), so later checks in the pass see the current mesh. Everyone whose cost inputs change
  // is re-ranked next pass.
  vertex_[from].touched = vertex_[to].touched = pass_;
  markChanged(from, target);
  if (textured()) moveWedges(from, to);
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
  }
  mergeFans(from, to);
  vertex_[from].removed = 1;
  target_[from] = to;
  quadrics_[to] += quadrics_[from];
  vertex_[to].selfCost = quadrics_[to].evaluate(position(to));
  // Per-vertex error bound: what `from` already stood for, plus how far it just moved off the
  // surface (model units). The table keeps the running maximum so it is monotone.
  vertex_[to].error = std::max(vertex_[to].error, vertex_[from].error + step);
  maxError_ = std::max(maxError_, vertex_[to].error);
  collapsed_.push_back(from);
  trianglesAfter_.push_back(triangleCount_ - static_cast<std::uint32_t>(removedTriangles_.size()));
  errorAfter_.push_back(static_cast<float>(maxError_));
}

void Simplifier::collapseAll() {
  std::vector<Candidate> ranked, scratch;
  while (true) {
    ++pass_;
    // Compact the fans once stale lists fill half the array.
    if (incident_.size() > 6 * std::size_t{triangleCount_ - removedTriangleCount()} + 4096)
      buildIncidence();
    if (options_.cost == CollapseCost::kMelax) updateFaceNormals();
    rankCollapses();
    // Drop the collapsed from the active list and list the candidates, in vertex order.
    ranked.clear();
    std::size_t kept = 0;
    for (std::uint32_t u : active_) {
      const VertexState& su = vertex_[u];
      if (su.removed) continue;
      active_[kept++] = u;
      if (su.bestTarget != kNone) ranked.emplace_back(su.bestCost, u);
    }
    active_.resize(kept);
    if (ranked.empty()) break;
    // The cheapest share first, in cost order; if none of those can collapse, the rest before
    // giving up.
    const std::size_t share = std::max<std::size_t>(
        1, static_cast<std::size_t>(kPassShare * static_cast<double>(ranked.size())));
    sortByCost(ranked, scratch);
    // Many small cost buckets, each walked in vertex order: neighbours in memory are neighbours
    // on the surface (fewer cache misses on big meshes), and the cost order barely changes.
    const std::size_t bucket = std::max<std::size_t>(1, share / kBuckets);
    for (std::size_t b = 0; b < share; b += bucket) {
      const auto first = ranked.begin() + static_cast<std::ptrdiff_t>(b);
      const auto last = ranked.begin() + static_cast<std::ptrdiff_t>(std::min(share, b + bucket));
      std::sort(first, last, [](const auto& x, const auto& y) { return x.second < y.second; });
    }
    const std::size_t before = collapsed_.size();
    for (std::size_t limit : {share, ranked.size()}) {
      passLimit_ = ranked[limit - 1].first;
      for (std::size_t i = 0; i < limit; ++i) {
        // The candidates are known ahead and scattered over the mesh: fetch their lines early.
        if (i + 8 < limit) {
          const std::uint32_t ahead = ranked[i + 8].second;
          __builtin_prefetch(&vertex_[ahead]);
        }
        if (i + 4 < limit) {
          const VertexState& ahead = vertex_[ranked[i + 4].second];
          __builtin_prefetch(&incident_[ahead.incidentStart]);
          __builtin_prefetch(&vertex_[ahead.bestTarget]);
        }
        if (i + 2 < limit) {
          const VertexState& ahead = vertex_[ranked[i + 2].second];
          for (std::uint32_t t : around(ranked[i + 2].second)) __builtin_prefetch(&corners_[t]);
          __builtin_prefetch(&incident_[vertex_[ahead.bestTarget].incidentStart]);
        }
        const std::uint32_t from = ranked[i].second;
        if (vertex_[from].touched == pass_ || vertex_[from].removed) continue;
        const Target to = validTarget(from, ranked[i].first);
        if (to.vertex == kNone) continue;
        // The error `to` would carry, as collapse() sets it. Refused past the bound; ranked
        // again next pass (its neighbourhood may change).
        const double step = stepDistance(from, to.vertex);
        if (options_.maxError > 0 &&
            std::max(vertex_[to.vertex].error, vertex_[from].error + step) > options_.maxError)
          continue;
        collapse(from, to, step);
        if (triangleCount_ - removedTriangleCount() <= options_.stopAtTriangles) return;
      }
      if (collapsed_.size() > before) break;
    }
    if (collapsed_.size() == before) break;  // nothing can collapse any more
  }
}

// PermuteT: surviving triangles first, then the removed ones, latest removal first.
std::vector<std::uint32_t> Simplifier::triangleOrder() const {
  std::vector<std::uint32_t> order(triangleCount_, kNone);
  std::uint32_t next = 0;
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    if (alive(t)) order[t] = next++;
  }
  const auto removedCount = static_cast<std::uint32_t>(removedTriangles_.size());
  for (std::uint32_t r = 0; r < removedCount; ++r)
    order[removedTriangles_[r]] = triangleCount_ - 1 - r;
  return order;
}

ProgressiveMesh Simplifier::rearrange(std::span<const Vec3f> normals,
                                      std::span<const Rgba8> colors) const {
  assert(!textured());  // rearrangeWedges
  ProgressiveMesh mesh;
  const auto collapses = static_cast<std::uint32_t>(collapsed_.size());
  mesh.q = vertexCount_ - collapses;
  // PermuteV: vertices that never collapse keep their order at the front; the k-th collapsed
  // vertex goes to p - 1 - k, so the first removed is last.
  mesh.permuteV.assign(vertexCount_, kNone);
  std::uint32_t next = 0;
  for (std::uint32_t v = 0; v < vertexCount_; ++v) {
    if (!vertex_[v].removed) mesh.permuteV[v] = next++;
  }
  for (std::uint32_t k = 0; k < collapses; ++k) mesh.permuteV[collapsed_[k]] = vertexCount_ - 1 - k;
  mesh.permuteT = triangleOrder();

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
    mesh.ecol[to] = vertex_[v].removed ? mesh.permuteV[target_[v]] : to;
    // The target always outlives the collapsed vertex, so it sits earlier: chains decrease.
    assert(!vertex_[v].removed || mesh.ecol[to] < to);
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

// The wedges of each point, in wedge order, from the corners (a wedge no corner names has no
// point and is left out).
struct PointWedges {
  std::vector<std::uint32_t> pointOf;  // per wedge, kNone when unused
  std::vector<std::uint32_t> first;    // per point + 1: where its wedges start in `wedges`
  std::vector<std::uint32_t> wedges;
  std::span<const std::uint32_t> of(std::uint32_t v) const {
    return std::span(wedges).subspan(first[v], first[v + 1] - first[v]);
  }
};

PointWedges groupWedges(std::span<const std::uint32_t> indices,
                        std::span<const std::uint32_t> cornerWedges, std::uint32_t points,
                        std::uint32_t wedgeCount) {
  PointWedges g;
  g.pointOf.assign(wedgeCount, kNone);
  for (std::size_t c = 0; c < indices.size(); ++c) g.pointOf[cornerWedges[c]] = indices[c];
  g.first.assign(points + 1, 0);
  for (std::uint32_t w = 0; w < wedgeCount; ++w)
    if (g.pointOf[w] != kNone) ++g.first[g.pointOf[w] + 1];
  for (std::uint32_t v = 0; v < points; ++v) g.first[v + 1] += g.first[v];
  g.wedges.resize(g.first.back());
  std::vector<std::uint32_t> next(g.first.begin(), g.first.end() - 1);
  for (std::uint32_t w = 0; w < wedgeCount; ++w)
    if (g.pointOf[w] != kNone) g.wedges[next[g.pointOf[w]]++] = w;
  return g;
}

// A textured mesh's progressive mesh is over its wedges: each wedge is a vertex with its point's
// position and its own coordinates, and a surface vertex's wedges leave together, latest
// collapse first, each into the wedge of its target that it was mapped to. So re-formation
// (Algorithm 2) works unchanged, and a count that leaves a vertex half collapsed is not whole.
ProgressiveMesh Simplifier::rearrangeWedges(std::span<const Vec3f> normals,
                                            std::span<const Rgba8> colors) const {
  const std::span<const Vec2f> uv = options_.wedgeUvs;
  const auto wedgeCount = static_cast<std::uint32_t>(uv.size());
  assert(normals.empty() || normals.size() == wedgeCount);
  assert(colors.empty() || colors.size() == wedgeCount);
  const PointWedges g = groupWedges(indices_, options_.wedges, vertexCount_, wedgeCount);
  ProgressiveMesh mesh;
  // PermuteV over wedges: those of points that never collapse first, then each collapsed
  // point's wedges together, the last collapse first.
  mesh.permuteV.assign(wedgeCount, kNone);
  std::uint32_t next = 0;
  for (std::uint32_t v = 0; v < vertexCount_; ++v)
    if (!vertex_[v].removed)
      for (std::uint32_t w : g.of(v)) mesh.permuteV[w] = next++;
  mesh.q = next;
  std::vector<std::uint32_t> groupStart(collapsed_.size());
  for (std::size_t k = collapsed_.size(); k-- > 0;) {
    groupStart[k] = next;
    for (std::uint32_t w : g.of(collapsed_[k])) mesh.permuteV[w] = next++;
  }
  const auto p = static_cast<std::uint32_t>(g.wedges.size());
  assert(next == p);
  mesh.permuteT = triangleOrder();
  mesh.positions.resize(p);
  mesh.uvs.resize(p);
  mesh.ecol.resize(p);
  if (!normals.empty()) mesh.normals.resize(p);
  if (!colors.empty()) mesh.colors.resize(p);
  for (std::uint32_t w = 0; w < wedgeCount; ++w) {
    const std::uint32_t to = mesh.permuteV[w], v = g.pointOf[w];
    if (to == kNone) continue;  // a wedge no triangle uses
    mesh.positions[to] = positions_[v];
    mesh.uvs[to] = uv[w];
    if (!normals.empty()) mesh.normals[to] = normals[w];
    if (!colors.empty()) mesh.colors[to] = colors[w];
    // A wedge no live triangle used when its point went (mapWedges left it out) goes to any
    // wedge of the target: no triangle that is drawn names it then.
    const std::uint32_t target = !vertex_[v].removed        ? w
                                 : wedgeTarget_[w] != kNone ? wedgeTarget_[w]
                                                            : g.of(target_[v]).front();
    mesh.ecol[to] = mesh.permuteV[target];
    assert(!vertex_[v].removed || mesh.ecol[to] < to);
  }
  mesh.triangles.resize(3 * std::size_t{triangleCount_});
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    for (std::size_t k = 0; k < 3; ++k)
      mesh.triangles[3 * std::size_t{mesh.permuteT[t]} + k] =
          mesh.permuteV[options_.wedges[3 * t + k]];
  }
  wedgeLevels(groupStart, mesh);
  return mesh;
}

// Map, error and the whole count at every n in [q, p]: a count inside a point's group of wedges
// is the mesh after that point's collapse, as far as map and error tell.
void Simplifier::wedgeLevels(std::span<const std::uint32_t> groupStart,
                             ProgressiveMesh& mesh) const {
  const std::uint32_t p = mesh.vertexCount(), levels = p - mesh.q + 1;
  mesh.map.assign(levels, triangleCount_);
  mesh.error.assign(levels, 0.0f);
  mesh.whole.resize(levels);
  mesh.whole[levels - 1] = p;
  for (std::size_t k = 0; k < groupStart.size(); ++k) {
    const std::uint32_t end = k == 0 ? p : groupStart[k - 1];
    for (std::uint32_t n = groupStart[k]; n < end; ++n) {
      mesh.map[n - mesh.q] = trianglesAfter_[k];
      mesh.error[n - mesh.q] = errorAfter_[k];
      mesh.whole[n - mesh.q] = groupStart[k];
    }
  }
}

// The mesh as the collapses left it: live triangles (corners are kept re-formed), vertices in
// order of first use.
SimplifiedMesh Simplifier::current() const {
  SimplifiedMesh out;
  std::vector<std::uint32_t> remap(vertexCount_, kNone);
  for (std::uint32_t t = 0; t < triangleCount_; ++t) {
    if (!alive(t)) continue;
    for (const std::uint32_t v : corners_[t]) {
      if (remap[v] == kNone) {
        remap[v] = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.push_back(v);
        out.border.push_back(border_[v]);
      }
      out.indices.push_back(remap[v]);
    }
    if (textured())
      out.wedges.insert(out.wedges.end(), wedgeCorners_[t].begin(), wedgeCorners_[t].end());
  }
  out.error = errorAfter_.empty() ? 0.0f : errorAfter_.back();
  // Where each removed vertex went: a collapse's target was live then, so it went later or not
  // at all; taking the collapses last first, each removed vertex inherits its target's place.
  out.representative = remap;
  for (auto k = collapsed_.size(); k-- > 0;)
    out.representative[collapsed_[k]] = out.representative[target_[collapsed_[k]]];
  return out;
}

}  // namespace

ProgressiveMesh buildProgressive(std::span<const Vec3f> positions,
                                 std::span<const std::uint32_t> indices,
                                 std::span<const Vec3f> normals, std::span<const Rgba8> colors,
                                 const ProgressiveOptions& options) {
  assert(indices.size() % 3 == 0);
  // Attributes are per vertex, or per wedge for a textured mesh.
  [[maybe_unused]] const std::size_t attributes =
      options.wedges.empty() ? positions.size() : options.wedgeUvs.size();
  assert(normals.empty() || normals.size() == attributes);
  assert(colors.empty() || colors.size() == attributes);
  Simplifier simplifier(positions, indices, options);
  simplifier.classifyBoundary();
  simplifier.computeQuadrics();
  simplifier.collapseAll();
  return options.wedges.empty() ? simplifier.rearrange(normals, colors)
                                : simplifier.rearrangeWedges(normals, colors);
}

SimplifiedMesh simplifyMesh(std::span<const Vec3f> positions,
                            std::span<const std::uint32_t> indices,
                            const ProgressiveOptions& options) {
  // The collapses of buildProgressive up to the target, without rearranging a progressive mesh
  // only to re-form one level of it.
  Simplifier simplifier(positions, indices, options);
  simplifier.classifyBoundary();
  simplifier.computeQuadrics();
  simplifier.collapseAll();
  return simplifier.current();
}

}  // namespace lodforge
