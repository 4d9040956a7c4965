#include "lodforge/runtime/stream.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "lodforge/simplify/reform.h"

namespace lodforge {

namespace {

constexpr std::uint64_t kTriangleBytes = 3 * sizeof(std::uint32_t);

// One copy of the buffer and the selection it holds.
struct BufferCopy {
  std::unique_ptr<Vec3f[]> positions, normals;
  std::unique_ptr<Rgba8[]> colors;
  std::unique_ptr<Vec2f[]> uvs;
  std::unique_ptr<std::uint32_t[]> source, indices;
  std::vector<std::uint64_t> vertexStart, triangleStart;  // objects + 1
  std::vector<std::uint32_t> vertexCounts, triangleCounts;

  void allocate(std::size_t objects, const StreamCapacity& capacity, bool withNormals,
                bool withColors, bool withUvs) {
    // Left uninitialised: only [0, count) is ever read, and it is always written first.
    positions = std::make_unique_for_overwrite<Vec3f[]>(capacity.vertices);
    if (withNormals) normals = std::make_unique_for_overwrite<Vec3f[]>(capacity.vertices);
    if (withColors) colors = std::make_unique_for_overwrite<Rgba8[]>(capacity.vertices);
    if (withUvs) uvs = std::make_unique_for_overwrite<Vec2f[]>(capacity.vertices);
    source = std::make_unique_for_overwrite<std::uint32_t[]>(3 * capacity.triangles);
    indices = std::make_unique_for_overwrite<std::uint32_t[]>(3 * capacity.triangles);
    vertexStart.assign(objects + 1, 0);
    triangleStart.assign(objects + 1, 0);
    vertexCounts.assign(objects, 0);
    triangleCounts.assign(objects, 0);
  }
  std::uint64_t vertices() const { return vertexStart.back(); }
  std::uint64_t triangles() const { return triangleStart.back(); }
};

double millisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// The object owning element `at` of a layout given by prefix sums: the last one starting at or
// before it (objects with nothing share their start with the next one and are passed over).
std::size_t owner(const std::vector<std::uint64_t>& start, std::uint64_t at) {
  return static_cast<std::size_t>(std::upper_bound(start.begin(), start.end(), at) - start.begin() -
                                  1);
}

// §3.3's reassembly of one array: destination element e of object i at local index l takes
// old[oldStart_i + l] when l < oldCount_i, else the package's element l of object i. Run per
// block of destinations: one binary search for the block's first owner, then whole runs.
template <class T, class PackageOffset>
void reassemble(const std::vector<std::uint64_t>& newStart,
                const std::vector<std::uint64_t>& oldStart, std::span<const std::uint32_t> oldCount,
                const T* old, const T* package, PackageOffset packageOffset, std::size_t width,
                T* out) {
  const std::uint64_t total = newStart.back();
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, total, 1 << 14),
                    [&](const tbb::blocked_range<std::uint64_t>& range) {
                      std::size_t i = owner(newStart, range.begin());
                      for (std::uint64_t at = range.begin(); at < range.end(); ++i) {
                        if (newStart[i + 1] <= at) continue;  // nothing selected of object i
                        const std::uint64_t end = std::min(range.end(), newStart[i + 1]);
                        const std::uint64_t local = at - newStart[i];
                        const std::uint64_t keptEnd = std::min(end, newStart[i] + oldCount[i]);
                        if (at < keptEnd) {
                          std::memcpy(out + width * at, old + width * (oldStart[i] + local),
                                      width * (keptEnd - at) * sizeof(T));
                          at = keptEnd;
                        }
                        if (at < end) {
                          std::memcpy(out + width * at,
                                      package + width * (packageOffset(i) + (at - newStart[i])),
                                      width * (end - at) * sizeof(T));
                          at = end;
                        }
                      }
                    });
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
  // Indices are 32-bit: the buffer can address at most 2^32 vertices.
  vertices = std::min<std::uint64_t>(vertices, std::numeric_limits<std::uint32_t>::max());
  const double ratio = triangleRatio(package);
  return {vertices, static_cast<std::uint64_t>(std::ceil(ratio * double(vertices)))};
}

StreamCapacity StreamCapacity::forMemory(const Package& package, std::uint64_t bytes) {
  const double ratio = triangleRatio(package);
  const double perVertex = 2.0 * (double(vertexBytes(package)) + ratio * 2.0 * kTriangleBytes);
  auto vertices = static_cast<std::uint64_t>(double(bytes) / perVertex);
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
  BufferCopy copies[2];
  int front = 0;

  BufferCopy& current() { return copies[front]; }
  const BufferCopy& current() const { return copies[front]; }
};

StreamBuffer::StreamBuffer(const Package& package, StreamCapacity capacity)
    : state_(std::make_unique<State>()) {
  assert(capacity.vertices <= std::numeric_limits<std::uint32_t>::max());
  state_->package = &package;
  state_->capacity = capacity;
  for (BufferCopy& copy : state_->copies)
    copy.allocate(package.objectCount(), capacity, package.header().hasNormals(),
                  package.header().hasColors(), package.header().hasUvs());
}

StreamBuffer::StreamBuffer(StreamBuffer&&) noexcept = default;
StreamBuffer& StreamBuffer::operator=(StreamBuffer&&) noexcept = default;
StreamBuffer::~StreamBuffer() = default;

void StreamBuffer::clear() {
  BufferCopy& c = state_->current();
  std::fill(c.vertexStart.begin(), c.vertexStart.end(), 0);
  std::fill(c.triangleStart.begin(), c.triangleStart.end(), 0);
  std::fill(c.vertexCounts.begin(), c.vertexCounts.end(), 0);
  std::fill(c.triangleCounts.begin(), c.triangleCounts.end(), 0);
}

namespace {

// The new layout: prefix sums of the counts, refused when it does not fit the capacity (only the
// back copy is touched; the front one still holds last frame).
Status layOut(const Package& package, const StreamCapacity& capacity,
              std::span<const std::uint32_t> vertexCounts,
              std::span<const std::uint32_t> triangleCounts, BufferCopy& next) {
  const std::size_t n = package.objectCount();
  std::copy(vertexCounts.begin(), vertexCounts.end(), next.vertexCounts.begin());
  std::copy(triangleCounts.begin(), triangleCounts.end(), next.triangleCounts.begin());
  for (std::size_t i = 0; i < n; ++i) {
    assert(vertexCounts[i] == 0 ? triangleCounts[i] == 0
                                : triangleCounts[i] == package.trianglesAt(i, vertexCounts[i]));
    next.vertexStart[i + 1] = next.vertexStart[i] + vertexCounts[i];
    next.triangleStart[i + 1] = next.triangleStart[i] + triangleCounts[i];
  }
  if (next.vertices() <= capacity.vertices && next.triangles() <= capacity.triangles) return {};
  return Error{ErrorKind::kLimit,
               fmt::format("{}: the selection ({} vertices, {} triangles) does not fit the "
                           "stream buffer ({} vertices, {} triangles)",
                           package.name(), next.vertices(), next.triangles(), capacity.vertices,
                           capacity.triangles)};
}

// What the frame reads and moves, per object: the kept part min(old, new), the read part
// new - kept; triangles of objects whose count changed are re-formed.
void tallyFrame(const Package& package, const BufferCopy& old,
                std::span<const std::uint32_t> vertexCounts,
                std::span<const std::uint32_t> triangleCounts, FrameStats& stats) {
  struct Tally {
    std::uint64_t vertexKept = 0, vertexRead = 0, triangleKept = 0, triangleRead = 0;
    std::uint64_t reformed = 0, indicesKept = 0, changed = 0;
  };
  const Tally tally = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, package.objectCount(), 1 << 14), Tally{},
      [&](const tbb::blocked_range<std::size_t>& range, Tally t) {
        for (std::size_t i = range.begin(); i < range.end(); ++i) {
          const std::uint32_t vo = old.vertexCounts[i], vn = vertexCounts[i];
          const std::uint32_t to = old.triangleCounts[i], tn = triangleCounts[i];
          t.vertexKept += std::min(vo, vn);
          t.vertexRead += vn - std::min(vo, vn);
          t.triangleKept += std::min(to, tn);
          t.triangleRead += tn - std::min(to, tn);
          if (vo == vn) {
            t.indicesKept += tn;
          } else {
            t.reformed += tn;
            ++t.changed;
          }
        }
        return t;
      },
      [](Tally a, const Tally& b) {
        a.vertexKept += b.vertexKept;
        a.vertexRead += b.vertexRead;
        a.triangleKept += b.triangleKept;
        a.triangleRead += b.triangleRead;
        a.reformed += b.reformed;
        a.indicesKept += b.indicesKept;
        a.changed += b.changed;
        return a;
      });
  const std::uint64_t vertexBytes = StreamCapacity::vertexBytes(package);
  stats.verticesRead = tally.vertexRead;
  stats.trianglesRead = tally.triangleRead;
  stats.bytesRead = tally.vertexRead * vertexBytes + tally.triangleRead * kTriangleBytes;
  stats.bytesMoved =
      tally.vertexKept * vertexBytes + (tally.triangleKept + tally.indicesKept) * kTriangleBytes;
  stats.trianglesReformed = tally.reformed;
  stats.trianglesKept = tally.indicesKept;
  stats.objectsChanged = tally.changed;
}

// §3.3: vertices and source triangles, each element from the old buffer or the package.
void reassembleFrame(const Package& package, const BufferCopy& old, BufferCopy& next) {
  const std::span<const PackageObject> objects = package.objects();
  const auto vertexOffset = [&](std::size_t i) { return objects[i].vertexOffset; };
  const auto triangleOffset = [&](std::size_t i) { return objects[i].triangleOffset; };
  const std::span<const std::uint32_t> oldVertexCounts(old.vertexCounts);
  reassemble(next.vertexStart, old.vertexStart, oldVertexCounts, old.positions.get(),
             package.allPositions().data(), vertexOffset, 1, next.positions.get());
  if (next.normals)
    reassemble(next.vertexStart, old.vertexStart, oldVertexCounts, old.normals.get(),
               package.allNormals().data(), vertexOffset, 1, next.normals.get());
  if (next.colors)
    reassemble(next.vertexStart, old.vertexStart, oldVertexCounts, old.colors.get(),
               package.allColors().data(), vertexOffset, 1, next.colors.get());
  if (next.uvs)
    reassemble(next.vertexStart, old.vertexStart, oldVertexCounts, old.uvs.get(),
               package.allUvs().data(), vertexOffset, 1, next.uvs.get());
  reassemble(next.triangleStart, old.triangleStart,
             std::span<const std::uint32_t>(old.triangleCounts), old.source.get(),
             package.allTriangles().data(), triangleOffset, 3, next.source.get());
}

// Algorithm 2 over every triangle whose object changed; the others keep last frame's indices,
// shifted by how far their object's vertices moved (beyond the paper, which re-forms all).
void reformFrame(const Package& package, const BufferCopy& old,
                 std::span<const std::uint32_t> vertexCounts, BufferCopy& next) {
  const std::span<const PackageObject> objects = package.objects();
  const std::uint32_t* ecolAll = package.allEcol().data();
  tbb::parallel_for(
      tbb::blocked_range<std::uint64_t>(0, next.triangles(), 1 << 13),
      [&](const tbb::blocked_range<std::uint64_t>& range) {
        std::size_t i = owner(next.triangleStart, range.begin());
        for (std::uint64_t at = range.begin(); at < range.end(); ++i) {
          if (next.triangleStart[i + 1] <= at) continue;
          const std::uint64_t end = std::min(range.end(), next.triangleStart[i + 1]);
          const std::uint32_t vn = vertexCounts[i];
          // Wraps modulo 2^32 when the object moved towards the front; the sum is exact.
          const auto base = static_cast<std::uint32_t>(next.vertexStart[i]);
          std::uint32_t* out = next.indices.get() + 3 * at;
          const std::size_t corners = 3 * (end - at);
          if (old.vertexCounts[i] == vn) {
            const std::uint32_t* from =
                old.indices.get() + 3 * (old.triangleStart[i] + (at - next.triangleStart[i]));
            const auto shift = static_cast<std::uint32_t>(next.vertexStart[i] - old.vertexStart[i]);
            for (std::size_t k = 0; k < corners; ++k) out[k] = from[k] + shift;
          } else {
            const std::uint32_t* from = next.source.get() + 3 * at;
            const std::uint32_t* ecol = ecolAll + objects[i].vertexOffset;
            for (std::size_t k = 0; k < corners; ++k)
              out[k] = reformCorner(from[k], vn, ecol) + base;
          }
          at = end;
        }
      });
}

}  // namespace

Result<FrameStats> StreamBuffer::update(std::span<const std::uint32_t> vertexCounts,
                                        std::span<const std::uint32_t> triangleCounts) {
  const Package& package = *state_->package;
  assert(vertexCounts.size() == package.objectCount() &&
         triangleCounts.size() == package.objectCount());
  const BufferCopy& old = state_->current();
  BufferCopy& next = state_->copies[1 - state_->front];
  FrameStats stats;
  const auto reassemblyStart = std::chrono::steady_clock::now();
  LODFORGE_TRY(layOut(package, state_->capacity, vertexCounts, triangleCounts, next));
  tallyFrame(package, old, vertexCounts, triangleCounts, stats);
  reassembleFrame(package, old, next);
  stats.reassemblyMs = millisecondsSince(reassemblyStart);
  const auto reformationStart = std::chrono::steady_clock::now();
  reformFrame(package, old, vertexCounts, next);
  stats.reformationMs = millisecondsSince(reformationStart);
  state_->front = 1 - state_->front;
  return stats;
}

const StreamCapacity& StreamBuffer::capacity() const {
  return state_->capacity;
}
std::uint64_t StreamBuffer::vertexCount() const {
  return state_->current().vertices();
}
std::uint64_t StreamBuffer::triangleCount() const {
  return state_->current().triangles();
}
std::span<const Vec3f> StreamBuffer::positions() const {
  return {state_->current().positions.get(), vertexCount()};
}
std::span<const Vec3f> StreamBuffer::normals() const {
  const auto& c = state_->current();
  return c.normals ? std::span<const Vec3f>(c.normals.get(), vertexCount())
                   : std::span<const Vec3f>();
}
std::span<const Rgba8> StreamBuffer::colors() const {
  const auto& c = state_->current();
  return c.colors ? std::span<const Rgba8>(c.colors.get(), vertexCount())
                  : std::span<const Rgba8>();
}
std::span<const Vec2f> StreamBuffer::uvs() const {
  const auto& c = state_->current();
  return c.uvs ? std::span<const Vec2f>(c.uvs.get(), vertexCount()) : std::span<const Vec2f>();
}
std::span<const std::uint32_t> StreamBuffer::sourceTriangles() const {
  return {state_->current().source.get(), 3 * triangleCount()};
}
std::span<const std::uint32_t> StreamBuffer::indices() const {
  return {state_->current().indices.get(), 3 * triangleCount()};
}
std::span<const std::uint64_t> StreamBuffer::vertexStart() const {
  return state_->current().vertexStart;
}
std::span<const std::uint64_t> StreamBuffer::triangleStart() const {
  return state_->current().triangleStart;
}
std::span<const std::uint32_t> StreamBuffer::vertexCounts() const {
  return state_->current().vertexCounts;
}

}  // namespace lodforge
