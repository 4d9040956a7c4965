#include "lodforge/runtime/stream.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include "lodforge/simplify/reform.h"

namespace lodforge {

namespace {

constexpr std::uint64_t kTriangleBytes = 3 * sizeof(std::uint32_t);
// Indices are 32-bit: the arena, twice the capacity, can address at most 2^32 vertices.
constexpr std::uint64_t kMostVertices = std::uint64_t{1} << 31;

// The arena: each array at twice the capacity (StreamCapacity::arenaVertices/arenaTriangles).
struct Arrays {
  std::unique_ptr<Vec3f[]> positions, normals;
  std::unique_ptr<Rgba8[]> colors;
  std::unique_ptr<Vec2f[]> uvs;
  std::unique_ptr<std::uint32_t[]> source, indices;
};

// A changed object this frame, and where its slot was before it (equal to its start unless it
// outgrew the slot and moved).
struct ObjectWork {
  std::uint32_t object = 0;
  std::uint64_t fromVertex = 0, fromTriangle = 0;
};

double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

std::uint64_t StreamCapacity::vertexBytes(const Package& package) {
  return sizeof(Vec3f) + (package.header().hasNormals() ? sizeof(Vec3f) : 0) +
         (package.header().hasColors() ? sizeof(Rgba8) : 0) +
         (package.header().hasUvs() ? sizeof(Vec2f) : 0);
}

double StreamCapacity::triangleRatio(const Package& package) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, package.objectCount(), 1024), 0.0,
      [&](const tbb::blocked_range<std::size_t>& range, double ratio) {
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
          const PackageObject& o = package.object(i);
          const auto map = package.map(i);
          for (std::size_t l = 0; l < map.size(); ++l) {
            const double n = double(o.minVertexCount) + double(l);
            if (n > 0) ratio = std::max(ratio, double(map[l]) / n);
          }
        }
        return ratio;
      },
      [](double a, double b) { return std::max(a, b); });
}

StreamCapacity StreamCapacity::forVertices(const Package& package, std::uint64_t vertices) {
  vertices = std::min(vertices, kMostVertices);
  const double ratio = triangleRatio(package);
  return {vertices, static_cast<std::uint64_t>(std::ceil(ratio * double(vertices)))};
}

StreamCapacity StreamCapacity::forMemory(const Package& package, std::uint64_t bytes) {
  const double ratio = triangleRatio(package);
  // The arena holds twice the capacity (stream.h).
  const double perVertex = 2.0 * (double(vertexBytes(package)) + ratio * 2.0 * kTriangleBytes);
  auto vertices = std::min(static_cast<std::uint64_t>(double(bytes) / perVertex), kMostVertices);
  StreamCapacity capacity{vertices,
                          static_cast<std::uint64_t>(std::ceil(ratio * double(vertices)))};
  // Rounding of the triangle count may tip it over by a few bytes: step back until it fits.
  while (capacity.vertices > 0 && capacity.bytes(package) > bytes) {
    --capacity.vertices;
    capacity.triangles = static_cast<std::uint64_t>(std::ceil(ratio * double(capacity.vertices)));
  }
  return capacity;
}

std::uint64_t StreamCapacity::bytes(const Package& package) const {
  return 2 * (vertices * vertexBytes(package) + triangles * 2 * kTriangleBytes);
}

struct StreamBuffer::State {
  const Package* package = nullptr;
  StreamCapacity capacity;
  Arrays arrays;
  // Per object: its slot (start and size) and what it holds.
  std::vector<std::uint64_t> vertexStart, triangleStart;
  std::vector<std::uint32_t> vertexSlot, triangleSlot, vertexCounts, triangleCounts;
  // Every object by where its slot starts, as of the last settleOrder(); objects relocated
  // since then are in `relocations` (in the order their slots were given, the last one counts).
  std::vector<std::uint32_t> order, relocations, lastRelocation;
  std::uint64_t vertexEnd = 0, triangleEnd = 0;      // the high-water mark: slots lie below
  std::uint64_t vertexTotal = 0, triangleTotal = 0;  // Σ counts
  std::vector<std::uint8_t> relocated;               // in `relocations`
  std::uint64_t update = 0, previous = 0;            // lastUpdate(), previousUpdate()
  bool compacted = false;                            // the last update packed the arena
  // The objects the last update changed: it works on them, and writtenRanges reads them after.
  std::vector<ObjectWork> work;
  mutable RangeScratch mergeScratch;  // writtenRanges's
  // Scratch for one update.
  std::vector<std::vector<ObjectWork>> blockWork;
  std::vector<std::uint32_t> nextOrder;
};

StreamBuffer::StreamBuffer(const Package& package, StreamCapacity capacity)
    : state_(std::make_unique<State>()) {
  assert(capacity.vertices <= kMostVertices);
  State& s = *state_;
  s.package = &package;
  s.capacity = capacity;
  // Left uninitialised: an object's [0, count) is written before anything reads it (the renderer
  // uploads the gaps between slots too, and never draws them).
  const std::uint64_t vertices = capacity.arenaVertices(), triangles = capacity.arenaTriangles();
  s.arrays.positions = std::make_unique_for_overwrite<Vec3f[]>(vertices);
  if (package.header().hasNormals())
    s.arrays.normals = std::make_unique_for_overwrite<Vec3f[]>(vertices);
  if (package.header().hasColors())
    s.arrays.colors = std::make_unique_for_overwrite<Rgba8[]>(vertices);
  if (package.header().hasUvs()) s.arrays.uvs = std::make_unique_for_overwrite<Vec2f[]>(vertices);
  s.arrays.source = std::make_unique_for_overwrite<std::uint32_t[]>(3 * triangles);
  s.arrays.indices = std::make_unique_for_overwrite<std::uint32_t[]>(3 * triangles);
  s.lastRelocation.assign(package.objectCount(), 0);
  clear();
}

StreamBuffer::StreamBuffer(StreamBuffer&&) noexcept = default;
StreamBuffer& StreamBuffer::operator=(StreamBuffer&&) noexcept = default;
StreamBuffer::~StreamBuffer() = default;

void StreamBuffer::clear() {
  State& s = *state_;
  const std::size_t n = s.package->objectCount();
  s.vertexStart.assign(n, 0);
  s.triangleStart.assign(n, 0);
  s.vertexSlot.assign(n, 0);
  s.triangleSlot.assign(n, 0);
  s.vertexCounts.assign(n, 0);
  s.triangleCounts.assign(n, 0);
  s.order.resize(n);
  std::iota(s.order.begin(), s.order.end(), 0u);
  s.relocations.clear();
  s.relocated.assign(n, 0);
  s.vertexEnd = s.triangleEnd = s.vertexTotal = s.triangleTotal = 0;
  s.work.clear();
  s.compacted = false;
}

namespace {

using Counts = std::span<const std::uint32_t>;

// Sums of vertices and triangles.
struct Totals {
  std::uint64_t vertices = 0, triangles = 0;
};

// Σ vc and Σ tc of the new selection (checked against the capacity before anything changes).
Totals sumCounts([[maybe_unused]] const Package& package, Counts vn, Counts tn) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, vn.size(), 1 << 14), Totals{},
      [&](const tbb::blocked_range<std::size_t>& range, Totals t) {
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
          assert(vn[i] == 0 ? tn[i] == 0 : tn[i] == package.trianglesAt(i, vn[i]));
          t.vertices += vn[i];
          t.triangles += tn[i];
        }
        return t;
      },
      [](Totals x, const Totals& y) {
        return Totals{x.vertices + y.vertices, x.triangles + y.triangles};
      });
}

// What the frame reads and re-forms, from the changed objects alone (an unchanged one reads
// nothing and keeps its indices): the read part new - min(old, new).
void tallyChanges(const StreamBuffer::State& s, Counts vn, Counts tn, const Totals& total,
                  FrameStats& stats) {
  for (const ObjectWork& w : s.work) {
    const std::uint32_t i = w.object;
    stats.verticesRead += vn[i] - std::min(s.vertexCounts[i], vn[i]);
    stats.trianglesRead += tn[i] - std::min(s.triangleCounts[i], tn[i]);
    stats.trianglesReformed += tn[i];
  }
  stats.bytesRead = stats.verticesRead * StreamCapacity::vertexBytes(*s.package) +
                    stats.trianglesRead * kTriangleBytes;
  stats.trianglesKept = total.triangles - stats.trianglesReformed;
  stats.objectsChanged = s.work.size();
}

// A selection beyond capacity is refused before anything changes.
Status checkFits(const Package& package, const StreamCapacity& capacity, const Totals& total) {
  if (total.vertices <= capacity.vertices && total.triangles <= capacity.triangles) return {};
  return Error{ErrorKind::kLimit,
               fmt::format("{}: the selection ({} vertices, {} triangles) does not fit the "
                           "stream buffer ({} vertices, {} triangles)",
                           package.name(), total.vertices, total.triangles, capacity.vertices,
                           capacity.triangles)};
}

bool outgrows(const StreamBuffer::State& s, std::size_t i, std::uint32_t vn, std::uint32_t tn) {
  return vn > s.vertexSlot[i] || tn > s.triangleSlot[i];
}

// This frame's changed objects in object order, and what those outgrowing their slots need
// (their exact counts; slack comes on top where it fits). Blocks of objects in parallel.
Totals collectChanged(StreamBuffer::State& s, Counts vn, Counts tn) {
  constexpr std::size_t kBlock = 1 << 14;
  const std::size_t blocks = (vn.size() + kBlock - 1) / kBlock;
  s.blockWork.resize(blocks);
  std::vector<Totals> needs(blocks);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    std::vector<ObjectWork>& work = s.blockWork[b];
    work.clear();
    for (std::size_t i = b * kBlock; i < std::min(vn.size(), (b + 1) * kBlock); ++i) {
      if (vn[i] == s.vertexCounts[i]) continue;
      work.push_back({static_cast<std::uint32_t>(i), s.vertexStart[i], s.triangleStart[i]});
      if (outgrows(s, i, vn[i], tn[i])) {
        needs[b].vertices += vn[i];
        needs[b].triangles += tn[i];
      }
    }
  });
  s.work.clear();
  Totals need;
  for (std::size_t b = 0; b < blocks; ++b) {
    s.work.insert(s.work.end(), s.blockWork[b].begin(), s.blockWork[b].end());
    need.vertices += needs[b].vertices;
    need.triangles += needs[b].triangles;
  }
  return need;
}

// Brings `order` up to date: objects relocated since the last call go to its end, in the order
// their slots were given (an object relocated twice, where its last slot was given). Done when the
// order is needed (a compaction, slotOrder), not every frame.
void settleOrder(StreamBuffer::State& s) {
  if (s.relocations.empty()) return;
  s.nextOrder.clear();
  for (const std::uint32_t i : s.order)
    if (!s.relocated[i]) s.nextOrder.push_back(i);
  for (std::size_t k = 0; k < s.relocations.size(); ++k) {
    const std::uint32_t i = s.relocations[k];
    if (s.lastRelocation[i] != k) continue;
    s.nextOrder.push_back(i);
    s.relocated[i] = 0;
  }
  s.relocations.clear();
  std::swap(s.order, s.nextOrder);
}

template <class T>
void moveDown(T* array, std::uint64_t from, std::uint64_t to, std::uint64_t count) {
  if (array && from != to && count) std::memmove(array + to, array + from, count * sizeof(T));
}

// After packing: the slots are their kept parts, back to back in slot order; what moved is
// counted (a kept part whose slot moved, and the indices of an object that did not grow when
// either of its slots moved).
void settleCompaction(StreamBuffer::State& s, Counts vn, Counts tn, FrameStats& stats) {
  const std::uint64_t vertexBytes = StreamCapacity::vertexBytes(*s.package);
  std::uint64_t vertexAt = 0, triangleAt = 0, moved = 0;
  for (const std::uint32_t i : s.order) {
    const std::uint32_t keptV = std::min(s.vertexCounts[i], vn[i]);
    const std::uint32_t keptT = std::min(s.triangleCounts[i], tn[i]);
    const bool vertexMoved = s.vertexStart[i] != vertexAt;
    const bool triangleMoved = s.triangleStart[i] != triangleAt;
    if (vertexMoved) moved += keptV * vertexBytes;
    if (triangleMoved) moved += keptT * kTriangleBytes;
    if ((vertexMoved || triangleMoved) && vn[i] <= s.vertexCounts[i])
      moved += keptT * kTriangleBytes;
    s.vertexStart[i] = vertexAt;
    s.triangleStart[i] = triangleAt;
    s.vertexSlot[i] = keptV;
    s.triangleSlot[i] = keptT;
    vertexAt += keptV;
    triangleAt += keptT;
  }
  s.vertexEnd = vertexAt;
  s.triangleEnd = triangleAt;
  stats.bytesMoved += moved;
  stats.compacted = true;
}

// Calls f(i, from, to, kept) for every object in slot order with where its kept part of one
// array (vertices or triangles) is and goes when the slots are packed.
template <class F>
void forEachPacked(const StreamBuffer::State& s, const std::vector<std::uint64_t>& start,
                   const std::vector<std::uint32_t>& counts, Counts next, F f) {
  std::uint64_t at = 0;
  for (const std::uint32_t i : s.order) {
    const std::uint32_t kept = std::min(counts[i], next[i]);
    f(i, start[i], at, kept);
    at += kept;
  }
}

// The arena is full: every slot shrinks to the part this frame keeps, packed in slot order.
// Each slot moves towards the front, so moving them in order never overwrites one not yet
// moved. The kept indices of an object that did not grow move with it, rebased (a shrinking
// object re-forms from them). The arrays are independent, so they are packed side by side.
void compact(StreamBuffer::State& s, Counts vn, Counts tn, FrameStats& stats) {
  Arrays& a = s.arrays;
  settleOrder(s);
  const auto packVertices = [&](auto* array) {
    if (!array) return;
    forEachPacked(s, s.vertexStart, s.vertexCounts, vn,
                  [&](std::uint32_t, std::uint64_t from, std::uint64_t to, std::uint32_t kept) {
                    moveDown(array, from, to, kept);
                  });
  };
  const auto packIndices = [&] {
    // The vertex slots' new starts first, then the indices moved and rebased by them.
    std::vector<std::uint64_t> vertexAt(s.order.size());
    forEachPacked(
        s, s.vertexStart, s.vertexCounts, vn,
        [&](std::uint32_t i, std::uint64_t, std::uint64_t to, std::uint32_t) { vertexAt[i] = to; });
    std::uint32_t* indices = a.indices.get();
    forEachPacked(s, s.triangleStart, s.triangleCounts, tn,
                  [&](std::uint32_t i, std::uint64_t from, std::uint64_t to, std::uint32_t kept) {
                    // A growing object is re-formed from its source triangles after this.
                    if (!kept || vn[i] > s.vertexCounts[i]) return;
                    if (from == to && vertexAt[i] == s.vertexStart[i]) return;
                    moveDown(indices, 3 * from, 3 * to, 3 * std::uint64_t{kept});
                    // Wraps modulo 2^32 when the vertices moved towards the front; exact.
                    const auto shift = static_cast<std::uint32_t>(vertexAt[i] - s.vertexStart[i]);
                    for (std::uint64_t c = 3 * to; c < 3 * (to + kept); ++c) indices[c] += shift;
                  });
  };
  tbb::parallel_invoke(
      [&] { packVertices(a.positions.get()); }, [&] { packVertices(a.normals.get()); },
      [&] {
        packVertices(a.colors.get());
        packVertices(a.uvs.get());
      },
      [&] {
        forEachPacked(s, s.triangleStart, s.triangleCounts, tn,
                      [&](std::uint32_t, std::uint64_t from, std::uint64_t to, std::uint32_t kept) {
                        moveDown(a.source.get(), 3 * from, 3 * to, 3 * std::uint64_t{kept});
                      });
      },
      packIndices);
  settleCompaction(s, vn, tn, stats);
}

// A slot with a quarter more room than the counts (no more than the whole object), so an object
// that keeps growing does not move every frame.
std::uint32_t withSlack(std::uint32_t count, std::uint32_t whole) {
  return static_cast<std::uint32_t>(
      std::min<std::uint64_t>(std::uint64_t{count} + count / 4, std::max(count, whole)));
}

// Objects that outgrew their slots get new ones at the high-water mark; their kept part is
// counted as moved.
void relocate(StreamBuffer::State& s, Counts vn, Counts tn, bool slack, FrameStats& stats) {
  const Package& package = *s.package;
  const std::uint64_t vertexBytes = StreamCapacity::vertexBytes(package);
  for (const ObjectWork& w : s.work) {
    const std::uint32_t i = w.object;
    if (!outgrows(s, i, vn[i], tn[i])) continue;
    const PackageObject& o = package.object(i);
    s.vertexSlot[i] = slack ? withSlack(vn[i], o.vertexCount) : vn[i];
    s.triangleSlot[i] = slack ? withSlack(tn[i], o.triangleCount) : tn[i];
    s.vertexStart[i] = s.vertexEnd;
    s.triangleStart[i] = s.triangleEnd;
    s.vertexEnd += s.vertexSlot[i];
    s.triangleEnd += s.triangleSlot[i];
    stats.bytesMoved += std::min(s.vertexCounts[i], vn[i]) * vertexBytes +
                        std::min(s.triangleCounts[i], tn[i]) * kTriangleBytes;
    s.relocated[i] = 1;
    s.lastRelocation[i] = static_cast<std::uint32_t>(s.relocations.size());
    s.relocations.push_back(i);
    ++stats.objectsRelocated;
  }
  assert(s.vertexEnd <= s.capacity.arenaVertices() && s.triangleEnd <= s.capacity.arenaTriangles());
  if (s.relocations.size() > s.order.size()) settleOrder(s);  // the log stays bounded
}

// Gives every changed object a slot that holds its new counts: in place while they fit, else
// at the high-water mark, after a compaction when even that is full.
void placeChanged(StreamBuffer::State& s, Counts vn, Counts tn, FrameStats& stats) {
  Totals need = collectChanged(s, vn, tn);
  const auto fits = [&](std::uint64_t v, std::uint64_t t) {
    return s.vertexEnd + v <= s.capacity.arenaVertices() &&
           s.triangleEnd + t <= s.capacity.arenaTriangles();
  };
  if (!fits(need.vertices, need.triangles)) {
    compact(s, vn, tn, stats);
    need = collectChanged(s, vn, tn);
  }
  relocate(s, vn, tn, fits(need.vertices + need.vertices / 4, need.triangles + need.triangles / 4),
           stats);
}

// One array of a changed object's slot: the kept part copied over when the slot moved, then
// [old, new) read from the package (§3.3's Δ).
template <class T>
void fillSlot(T* arena, const T* package, std::uint64_t packageOffset, std::uint64_t width,
              std::uint64_t from, std::uint64_t to, std::uint32_t oldCount,
              std::uint32_t newCount) {
  if (!arena) return;
  const std::uint64_t kept = std::min(oldCount, newCount);
  if (from != to && kept)
    std::memcpy(arena + width * to, arena + width * from, width * kept * sizeof(T));
  if (newCount > oldCount)
    std::memcpy(arena + width * (to + oldCount), package + width * (packageOffset + oldCount),
                width * (newCount - oldCount) * sizeof(T));
}

// §3.3's reassembly, for the changed objects only: the others' slots hold this frame already.
void reassembleChanged(StreamBuffer::State& s, Counts vn, Counts tn) {
  const Package& package = *s.package;
  Arrays& a = s.arrays;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.work.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k < range.end(); ++k) {
                        const ObjectWork& w = s.work[k];
                        const std::uint32_t i = w.object;
                        const PackageObject& o = package.object(i);
                        const std::uint64_t v = s.vertexStart[i], vOffset = o.vertexOffset;
                        const std::uint32_t vo = s.vertexCounts[i];
                        fillSlot(a.positions.get(), package.allPositions().data(), vOffset, 1,
                                 w.fromVertex, v, vo, vn[i]);
                        fillSlot(a.normals.get(), package.allNormals().data(), vOffset, 1,
                                 w.fromVertex, v, vo, vn[i]);
                        fillSlot(a.colors.get(), package.allColors().data(), vOffset, 1,
                                 w.fromVertex, v, vo, vn[i]);
                        fillSlot(a.uvs.get(), package.allUvs().data(), vOffset, 1, w.fromVertex, v,
                                 vo, vn[i]);
                        fillSlot(a.source.get(), package.allTriangles().data(), o.triangleOffset, 3,
                                 w.fromTriangle, s.triangleStart[i], s.triangleCounts[i], tn[i]);
                      }
                    });
}

// Starts fetching an object's ECol: a changed object's chains start with a cache miss each, and
// its ECol (about 1 KB for a CAD part) is rarely in cache. Up to 4 KB.
void prefetchEcol(const std::uint32_t* ecol, std::uint32_t vertices) {
  constexpr std::uint32_t kLineWords = 16, kMaxLines = 64;
  const std::uint32_t lines = std::min(kMaxLines, (vertices + kLineWords - 1) / kLineWords);
  for (std::uint32_t l = 0; l < lines; ++l) __builtin_prefetch(ecol + l * kLineWords);
}

// Algorithm 2 over the changed objects' triangles (beyond the paper, which re-forms all: an
// unchanged object's indices stay valid in its slot). A shrinking object starts each corner's
// walk from last frame's index, which lies on the same ECol chain further down. Large objects
// are split further.
void reformChanged(StreamBuffer::State& s, Counts vn, Counts tn) {
  const Package& package = *s.package;
  const std::uint32_t* ecolAll = package.allEcol().data();
  const auto ecolOf = [&](std::uint32_t i) { return ecolAll + package.object(i).vertexOffset; };
  const auto reformRange = [&](std::uint32_t i, std::uint64_t begin, std::uint64_t end) {
    const std::uint32_t* ecol = ecolOf(i);
    const auto base = static_cast<std::uint32_t>(s.vertexStart[i]);
    std::uint32_t* out = s.arrays.indices.get() + 3 * s.triangleStart[i];
    if (vn[i] < s.vertexCounts[i]) {
      for (std::uint64_t k = begin; k < end; ++k)
        out[k] = reformCorner(out[k] - base, vn[i], ecol) + base;
      return;
    }
    const std::uint32_t* from = s.arrays.source.get() + 3 * s.triangleStart[i];
    for (std::uint64_t k = begin; k < end; ++k) out[k] = reformCorner(from[k], vn[i], ecol) + base;
  };
  constexpr std::uint64_t kSplitCorners = 3 << 15;
  constexpr std::size_t kPrefetchAhead = 4;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.work.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k < range.end(); ++k) {
                        if (k + kPrefetchAhead < range.end()) {
                          const std::uint32_t ahead = s.work[k + kPrefetchAhead].object;
                          prefetchEcol(ecolOf(ahead), package.object(ahead).vertexCount);
                        }
                        const std::uint32_t i = s.work[k].object;
                        const std::uint64_t corners = 3 * std::uint64_t{tn[i]};
                        if (corners < 2 * kSplitCorners) {
                          reformRange(i, 0, corners);
                          continue;
                        }
                        tbb::parallel_for(
                            tbb::blocked_range<std::uint64_t>(0, corners, kSplitCorners),
                            [&](const tbb::blocked_range<std::uint64_t>& r) {
                              reformRange(i, r.begin(), r.end());
                            });
                      }
                    });
}

}  // namespace

Result<FrameStats> StreamBuffer::update(std::span<const std::uint32_t> vertexCounts,
                                        std::span<const std::uint32_t> triangleCounts) {
  State& s = *state_;
  const Package& package = *s.package;
  assert(vertexCounts.size() == package.objectCount() &&
         triangleCounts.size() == package.objectCount());
  FrameStats stats;
  const auto reassemblyStart = std::chrono::steady_clock::now();
  const Totals total = sumCounts(package, vertexCounts, triangleCounts);
  LODFORGE_TRY(checkFits(package, s.capacity, total));
  placeChanged(s, vertexCounts, triangleCounts, stats);
  tallyChanges(s, vertexCounts, triangleCounts, total, stats);
  reassembleChanged(s, vertexCounts, triangleCounts);
  stats.reassemblyMs = millisecondsSince(reassemblyStart);
  const auto reformationStart = std::chrono::steady_clock::now();
  reformChanged(s, vertexCounts, triangleCounts);
  stats.reformationMs = millisecondsSince(reformationStart);
  for (const ObjectWork& w : s.work) {
    s.vertexCounts[w.object] = vertexCounts[w.object];
    s.triangleCounts[w.object] = triangleCounts[w.object];
  }
  s.vertexTotal = total.vertices;
  s.triangleTotal = total.triangles;
  s.compacted = stats.compacted;
  static std::atomic<std::uint64_t> updates{0};
  s.previous = s.update;
  s.update = ++updates;
  return stats;
}

std::uint64_t StreamBuffer::lastUpdate() const {
  return state_->update;
}
std::uint64_t StreamBuffer::previousUpdate() const {
  return state_->previous;
}

void StreamBuffer::writtenRanges(std::size_t maxRanges, std::vector<Range>& vertices,
                                 std::vector<Range>& triangles) const {
  const State& s = *state_;
  vertices.clear();
  triangles.clear();
  if (s.compacted) {
    // Packing moved every slot.
    if (s.vertexEnd) vertices.push_back({0, s.vertexEnd});
    if (s.triangleEnd) triangles.push_back({0, s.triangleEnd});
    return;
  }
  // Only the changed objects' slots were written (reassembly, relocation and re-formation).
  for (const ObjectWork& w : s.work) {
    const std::uint32_t i = w.object;
    if (s.vertexCounts[i])
      vertices.push_back({s.vertexStart[i], s.vertexStart[i] + s.vertexCounts[i]});
    if (s.triangleCounts[i])
      triangles.push_back({s.triangleStart[i], s.triangleStart[i] + s.triangleCounts[i]});
  }
  mergeRanges(vertices, maxRanges, s.mergeScratch);
  mergeRanges(triangles, maxRanges, s.mergeScratch);
}

void StreamBuffer::rangesSince(std::uint64_t held, std::size_t maxRanges,
                               std::vector<Range>& vertices, std::vector<Range>& triangles) const {
  const State& s = *state_;
  if (held != 0 && held == s.update) {
    vertices.clear();
    triangles.clear();
  } else if (held != 0 && held == s.previous) {
    writtenRanges(maxRanges, vertices, triangles);
  } else {
    vertices.assign(1, {0, s.vertexEnd});
    triangles.assign(1, {0, s.triangleEnd});
  }
}

const StreamCapacity& StreamBuffer::capacity() const {
  return state_->capacity;
}
std::uint64_t StreamBuffer::vertexCount() const {
  return state_->vertexTotal;
}
std::uint64_t StreamBuffer::triangleCount() const {
  return state_->triangleTotal;
}
std::span<const Vec3f> StreamBuffer::positions() const {
  return {state_->arrays.positions.get(), state_->vertexEnd};
}
std::span<const Vec3f> StreamBuffer::normals() const {
  const State& s = *state_;
  return s.arrays.normals ? std::span<const Vec3f>(s.arrays.normals.get(), s.vertexEnd)
                          : std::span<const Vec3f>();
}
std::span<const Rgba8> StreamBuffer::colors() const {
  const State& s = *state_;
  return s.arrays.colors ? std::span<const Rgba8>(s.arrays.colors.get(), s.vertexEnd)
                         : std::span<const Rgba8>();
}
std::span<const Vec2f> StreamBuffer::uvs() const {
  const State& s = *state_;
  return s.arrays.uvs ? std::span<const Vec2f>(s.arrays.uvs.get(), s.vertexEnd)
                      : std::span<const Vec2f>();
}
std::span<const std::uint32_t> StreamBuffer::sourceTriangles() const {
  return {state_->arrays.source.get(), 3 * state_->triangleEnd};
}
std::span<const std::uint32_t> StreamBuffer::indices() const {
  return {state_->arrays.indices.get(), 3 * state_->triangleEnd};
}
std::span<const std::uint64_t> StreamBuffer::vertexStart() const {
  return state_->vertexStart;
}
std::span<const std::uint64_t> StreamBuffer::triangleStart() const {
  return state_->triangleStart;
}
std::span<const std::uint32_t> StreamBuffer::vertexCounts() const {
  return state_->vertexCounts;
}
std::span<const std::uint32_t> StreamBuffer::triangleCounts() const {
  return state_->triangleCounts;
}
std::span<const std::uint32_t> StreamBuffer::slotOrder() const {
  settleOrder(*state_);
  return state_->order;
}

}  // namespace lodforge
