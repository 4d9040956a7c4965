// Algorithm 2 on the GPU, as the CAD paper runs it (§3.2): ECol of every object stays resident in
// a shader storage buffer; per frame the stream's source triangles and a table of the selected
// objects go up, and one compute invocation per triangle finds its object by binary search over
// the objects' first triangles (in the order of the stream's slots), then follows ECol until every
// corner is below the object's vertex count. The result lands in the renderer's index buffer.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/render/gpu_stream.h"
#include "lodforge/runtime/stream.h"
#include "lodforge/simplify/package.h"

namespace lodforge {

class GpuReformer {
 public:
  // Needs a current GL 4.5 context; uploads the package's ECol once.
  static Result<GpuReformer> create(const Package& package, const StreamCapacity& capacity);
  GpuReformer(GpuReformer&&) noexcept;
  GpuReformer& operator=(GpuReformer&&) noexcept;
  ~GpuReformer();

  // Re-forms the stream buffer's source triangles into `indexBuffer` (a GL buffer as large as
  // buffer.indices()): each object's slot gets the indices the CPU path puts there.
  void reform(const StreamBuffer& buffer, unsigned indexBuffer);
  // The same from a GPU stream, whose source triangles are already on the GPU.
  void reform(const GpuStream& stream, unsigned indexBuffer);
  // Bytes the last reform copied to the GL: the source triangles the stream's update wrote (all
  // of them when the GL copy is not the update before) and the object table.
  std::uint64_t uploadedBytes() const;
  // Reads back the first `triangles` triangles of a GL index buffer (tests, debugging).
  static std::vector<std::uint32_t> readIndices(unsigned indexBuffer, std::uint64_t triangles);

 private:
  struct State;
  explicit GpuReformer(std::unique_ptr<State> state);
  // Objects by their first triangle in `order` (empty: object order); their triangles may be
  // apart, the gaps are skipped.
  struct Objects {
    std::span<const std::uint32_t> vertexCounts, triangleCounts, order;
    std::span<const std::uint64_t> vertexStart, triangleStart;
  };
  void run(unsigned sourceBuffer, const Objects& objects, unsigned indexBuffer);
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
