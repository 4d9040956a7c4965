// One frame's way from a selection to the screen, in the three arrangements the tools offer:
//   kCpu           CPU stream (§3.3) and CPU reformation (Algorithm 2), used ranges uploaded
//   kCpuGpuReform  CPU stream, indices re-formed in a compute shader (§3.2)
//   kGpu           the paper's arrangement: only the Δ is uploaded, reassembly and
//                  reformation run on the GPU
// `lodforge render`, `bench --render` and `view` all go through it.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "lodforge/core/status.h"
#include "lodforge/render/renderer.h"
#include "lodforge/runtime/stream.h"
#include "lodforge/simplify/package.h"

namespace lodforge {

enum class Streaming : std::uint8_t { kCpu, kCpuGpuReform, kGpu };
const char* streamingName(Streaming mode);  // "cpu", "cpu-stream-gpu-reform", "gpu"

struct PipelineTimings {
  double streamMs = 0;  // CPU: reassembly + reformation; GPU: Δ upload + reassembly
  double uploadMs = 0;  // CPU stream: what the last update wrote to the GL
  // CPU stream: bytes that upload (the vertex and index arrays, the commands) and the GPU
  // reformer (source triangles, object table) copied to the GL. Not counted for the GPU stream.
  std::uint64_t uploadedBytes = 0;
  double reformMs = 0;  // GPU reformation (0 when the CPU re-forms, inside streamMs)
  double drawMs = 0;
};

class FramePipeline {
 public:
  // Needs a current GL 4.5 context. With `switchable`, every arrangement is prepared so that
  // setStreaming() can change it between frames (the viewer); otherwise only `mode`'s parts.
  static Result<FramePipeline> create(const Package& package, const StreamCapacity& capacity,
                                      Streaming mode, bool switchable = false);
  FramePipeline(FramePipeline&&) noexcept;
  FramePipeline& operator=(FramePipeline&&) noexcept;
  ~FramePipeline();

  void setStreaming(Streaming mode);  // needs `switchable`
  Streaming streaming() const;
  // Brings the GL buffers to this selection (tc_i = map(vc_i)); each step is timed to glFinish.
  Result<FrameStats> update(std::span<const std::uint32_t> vertexCounts,
                            std::span<const std::uint32_t> triangleCounts);
  // Draws into the bound framebuffer, timed to glFinish.
  void draw(const Camera& camera, const DrawOptions& options);
  const PipelineTimings& timings() const;

 private:
  struct State;
  explicit FramePipeline(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
