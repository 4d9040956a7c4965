// §3.3 on the GPU, as the CAD paper streams: the frame's vertices and source triangles live in
// two copies of GL buffers in object order; each frame only what the new selection adds (the Δ
// ranges, read from the package) crosses to the GPU, and a compute shader assembles the new copy
// from the old one and those ranges. GpuReformer then re-forms the indices from the source
// triangles already on the GPU (Algorithm 2), and Renderer draws from these buffers.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "lodforge/core/status.h"
#include "lodforge/runtime/stream.h"
#include "lodforge/simplify/package.h"

namespace lodforge {

class GpuStream {
 public:
  // Needs a current GL 4.5 context; both copies hold `capacity`.
  static Result<GpuStream> create(const Package& package, const StreamCapacity& capacity);
  GpuStream(GpuStream&&) noexcept;
  GpuStream& operator=(GpuStream&&) noexcept;
  ~GpuStream();

  // As StreamBuffer::update: tc_i = map(vc_i); over capacity: kLimit and nothing changes.
  // bytesRead counts what crossed to the GPU from the package, bytesMoved what the GPU copied.
  Result<FrameStats> update(std::span<const std::uint32_t> vertexCounts,
                            std::span<const std::uint32_t> triangleCounts);

  const Package& package() const;
  const StreamCapacity& capacity() const;
  std::uint64_t vertexCount() const;
  std::uint64_t triangleCount() const;
  std::span<const std::uint64_t> vertexStart() const;    // objects + 1
  std::span<const std::uint64_t> triangleStart() const;  // objects + 1
  std::span<const std::uint32_t> vertexCounts() const;
  std::span<const std::uint32_t> triangleCounts() const;
  // The current copy's GL buffers (0 when the package has no normals / colours / uvs).
  unsigned positionBuffer() const;
  unsigned normalBuffer() const;
  unsigned colorBuffer() const;
  unsigned uvBuffer() const;
  unsigned sourceBuffer() const;  // 3 uint32 per triangle, object-local corners

 private:
  struct State;
  explicit GpuStream(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
