// Frame-coherent streaming after the CAD paper §3.3: a buffer of fixed capacity holds the selected
// vertices and triangles of all objects, and each frame only the ranges that changed are read from
// the package. The buffer stands for GPU memory; the renderer uploads or maps its arrays.
//
// Beyond the paper, the buffer is updated in place: each object owns a slot, a range of the
// vertex and triangle arrays at least as large as its counts, and keeps it while its selection
// fits. The paper rebuilds the compact layout (objects back to back) every frame, which moves
// every unchanged object behind the first changed one: at 18 M triangles, 1.3 GB per frame. An
// object that outgrows its slot moves to a new one at the end of the arena; when the arena
// (twice the capacity) is full, one compaction packs the slots in their order.
//
// Per object i with vc_i vertices and tc_i = map(vc_i) triangles, its slot holds
//   vertices      positions (and normals, colors, uvs when the package has them) [0, vc_i)
//   source        the first tc_i rearranged triangles, object-local full-detail corners
//   indices       the same triangles re-formed at vc_i (Algorithm 2), as indices into the
//                 whole vertex buffer, so one multi-draw (a command per object) renders the frame
// Source triangles are streamed like vertices (only [tc_old, tc_new) is read), as in the paper,
// where they live in GPU memory and re-formation runs there. ECol and Map are read in place
// from the package, as the paper keeps them resident on the GPU. Between slots the arrays hold
// stale data: read an object's ranges through vertexStart/triangleStart and its counts.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/ranges.h"
#include "lodforge/core/status.h"
#include "lodforge/simplify/package.h"

namespace lodforge {

// What one selection may hold. Triangles follow from vertices by the package's largest ratio of
// triangles to vertices over every object and level, so no selection within the vertex budget
// can overflow them. The buffer's arrays (the arena) hold twice this, so that objects which
// outgrow their slots have room before a compaction; indices are 32-bit, so forVertices and
// forMemory give at most 2^31 vertices.
struct StreamCapacity {
  std::uint64_t vertices = 0;
  std::uint64_t triangles = 0;

  std::uint64_t arenaVertices() const { return 2 * vertices; }
  std::uint64_t arenaTriangles() const { return 2 * triangles; }
  // GL draws and the GPU reformer address the arena's corners with 32-bit offsets.
  bool arenaFitsGpuOffsets() const {
    return arenaVertices() < (std::uint64_t{1} << 32) &&
           3 * arenaTriangles() < (std::uint64_t{1} << 32);
  }

  // Bytes per vertex (position, plus normal, color and uv when the package has them).
  static std::uint64_t vertexBytes(const Package& package);
  // max over objects and levels n of map(n) / n.
  static double triangleRatio(const Package& package);
  static StreamCapacity forVertices(const Package& package, std::uint64_t vertices);
  // The most vertices whose arena — vertices, source triangles and indices, each twice the
  // capacity — fits in `bytes`.
  static StreamCapacity forMemory(const Package& package, std::uint64_t bytes);
  // Bytes of the arena.
  std::uint64_t bytes(const Package& package) const;
};

// What a frame cost. "Read" is data taken from the package (the repository); "moved" is data
// copied inside the buffer: the kept part of objects that outgrew their slots and, in a frame
// that compacts, every slot that moved (with the indices of objects that did not grow, rebased).
struct FrameStats {
  std::uint64_t bytesRead = 0;
  std::uint64_t bytesMoved = 0;
  std::uint64_t verticesRead = 0, trianglesRead = 0;
  std::uint64_t trianglesReformed = 0;  // objects whose count changed: re-formed from source
  std::uint64_t trianglesKept = 0;      // objects whose count did not: indices kept
  std::uint64_t objectsChanged = 0;
  std::uint64_t objectsRelocated = 0;  // changed objects that outgrew their slot
  bool compacted = false;              // the arena was full: slots packed in their order
  double reassemblyMs = 0;             // vertices and source triangles into the new buffer
  double reformationMs = 0;            // indices: re-formed or kept
};

class StreamBuffer {
 public:
  StreamBuffer(const Package& package, StreamCapacity capacity);
  StreamBuffer(StreamBuffer&&) noexcept;
  StreamBuffer& operator=(StreamBuffer&&) noexcept;
  ~StreamBuffer();

  // Makes the buffer hold the objects at these counts (tc_i must be map(vc_i), 0 with vc_i = 0;
  // the sums must fit the capacity, else a kLimit error and the buffer is unchanged). Reads
  // only what last frame's buffer lacks; an unchanged object's slot is not touched.
  Result<FrameStats> update(std::span<const std::uint32_t> vertexCounts,
                            std::span<const std::uint32_t> triangleCounts);
  // Forgets last frame, so the next update reads everything (a from-scratch build).
  void clear();

  // The last successful update, by a number unique in the process (0 before any), and the one
  // it followed. A copy of the arrays (the GPU's) that held them after update `previousUpdate()`
  // holds them after `lastUpdate()` once it takes what writtenRanges() gives.
  std::uint64_t lastUpdate() const;
  std::uint64_t previousUpdate() const;
  // In elements: vertices for the vertex arrays, triangles for source and indices.
  using Range = ElementRange;
  // What the last update wrote, as sorted disjoint ranges: every changed object's slot, or the
  // whole used arena when it compacted. At most `maxRanges` of each: the closest are merged
  // (a copy of the stale space between them costs less than a call per object).
  void writtenRanges(std::size_t maxRanges, std::vector<Range>& vertices,
                     std::vector<Range>& triangles) const;
  // What a copy that holds update `held` (0: nothing known) must take to hold lastUpdate():
  // nothing when it holds it, writtenRanges after the update before, else the arrays up to the
  // high-water mark whole.
  void rangesSince(std::uint64_t held, std::size_t maxRanges, std::vector<Range>& vertices,
                   std::vector<Range>& triangles) const;
  // The ranges a GL copy takes per array and frame at most: each is a driver call, so the 18,000
  // changed objects of a frame at 718 K parts are merged into this many, the closest first.
  static constexpr std::size_t kUploadRanges = 512;

  const StreamCapacity& capacity() const;
  std::uint64_t vertexCount() const;    // Σ vc_i
  std::uint64_t triangleCount() const;  // Σ tc_i
  // The arrays up to the arena's high-water mark (slots and the stale space between them).
  std::span<const Vec3f> positions() const;
  std::span<const Vec3f> normals() const;                  // empty without normals in the package
  std::span<const Rgba8> colors() const;                   // empty without colors
  std::span<const Vec2f> uvs() const;                      // empty unless textured
  std::span<const std::uint32_t> sourceTriangles() const;  // 3 per triangle, object-local
  std::span<const std::uint32_t> indices() const;          // 3 per triangle, buffer-global
  // Per object (one entry each): where its slot's vertices and triangles start, and its counts.
  std::span<const std::uint64_t> vertexStart() const;
  std::span<const std::uint64_t> triangleStart() const;
  std::span<const std::uint32_t> vertexCounts() const;
  std::span<const std::uint32_t> triangleCounts() const;
  // Every object once, by where its slot starts (vertices and triangles are in the same order).
  // Brings the order up to date first, so no other call may run beside it.
  std::span<const std::uint32_t> slotOrder() const;

  struct State;  // (its helpers in stream.cpp take it)

 private:
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
