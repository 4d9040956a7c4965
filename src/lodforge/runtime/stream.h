// Frame-coherent streaming of the CAD paper §3.3: a buffer of fixed capacity holds the selected
// vertices and triangles of all objects, back to back in object order (the VBO layout), and each
// frame only the ranges that changed are read from the package; the rest is moved from last
// frame's buffer. The buffer stands for GPU memory; the renderer uploads or maps its arrays.
//
// Per object i with vc_i vertices and tc_i = map(vc_i) triangles the buffer holds
//   vertices      positions (and normals, colors, uvs when the package has them) [0, vc_i)
//   source        the first tc_i rearranged triangles, object-local full-detail corners
//   indices       the same triangles re-formed at vc_i (Algorithm 2), as indices into the
//                 whole vertex buffer, so one draw call renders the frame
// Source triangles are streamed like vertices (only [tc_old, tc_new) is read), as in the paper,
// where they live in GPU memory and re-formation runs there. ECol and Map are read in place
// from the package, as the paper keeps them resident on the GPU.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/status.h"
#include "lodforge/simplify/package.h"

namespace lodforge {

// What one buffer copy can hold. Triangles follow from vertices by the package's largest ratio
// of triangles to vertices over every object and level, so no selection within the vertex
// budget can overflow them.
struct StreamCapacity {
  std::uint64_t vertices = 0;
  std::uint64_t triangles = 0;

  // Bytes per vertex (position, plus normal, color and uv when the package has them).
  static std::uint64_t vertexBytes(const Package& package);
  // max over objects and levels n of map(n) / n.
  static double triangleRatio(const Package& package);
  static StreamCapacity forVertices(const Package& package, std::uint64_t vertices);
  // The most vertices whose buffers — both copies of vertices, source triangles and indices —
  // fit in `bytes`.
  static StreamCapacity forMemory(const Package& package, std::uint64_t bytes);
  // Bytes of both copies.
  std::uint64_t bytes(const Package& package) const;
};

// What a frame cost. "Read" is data taken from the package (the repository); "moved" is data
// copied from last frame's buffer.
struct FrameStats {
  std::uint64_t bytesRead = 0;
  std::uint64_t bytesMoved = 0;
  std::uint64_t verticesRead = 0, trianglesRead = 0;
  std::uint64_t trianglesReformed = 0;  // objects whose count changed: re-formed from source
  std::uint64_t trianglesKept = 0;      // objects whose count did not: indices moved and rebased
  std::uint64_t objectsChanged = 0;
  double reassemblyMs = 0;   // vertices and source triangles into the new buffer
  double reformationMs = 0;  // indices: re-formed or kept
};

class StreamBuffer {
 public:
  StreamBuffer(const Package& package, StreamCapacity capacity);
  StreamBuffer(StreamBuffer&&) noexcept;
  StreamBuffer& operator=(StreamBuffer&&) noexcept;
  ~StreamBuffer();

  // Makes the buffer hold the objects at these counts (tc_i must be map(vc_i), 0 with vc_i = 0;
  // the sums must fit the capacity, else a kLimit error and the buffer is unchanged). Reads
  // only what last frame's buffer lacks.
  Result<FrameStats> update(std::span<const std::uint32_t> vertexCounts,
                            std::span<const std::uint32_t> triangleCounts);
  // Forgets last frame, so the next update reads everything (a from-scratch build).
  void clear();

  const StreamCapacity& capacity() const;
  std::uint64_t vertexCount() const;
  std::uint64_t triangleCount() const;
  std::span<const Vec3f> positions() const;
  std::span<const Vec3f> normals() const;                  // empty without normals in the package
  std::span<const Rgba8> colors() const;                   // empty without colors
  std::span<const Vec2f> uvs() const;                      // empty unless textured
  std::span<const std::uint32_t> sourceTriangles() const;  // 3 per triangle, object-local
  std::span<const std::uint32_t> indices() const;          // 3 per triangle, buffer-global
  // Per object: where its vertices and triangles start (object count + 1 entries) and counts.
  std::span<const std::uint64_t> vertexStart() const;
  std::span<const std::uint64_t> triangleStart() const;
  std::span<const std::uint32_t> vertexCounts() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
