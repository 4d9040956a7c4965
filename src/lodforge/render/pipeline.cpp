#include "lodforge/render/pipeline.h"

#include <cassert>
#include <chrono>
#include <optional>

#include <epoxy/gl.h>

#include "lodforge/render/gpu_reform.h"
#include "lodforge/render/gpu_stream.h"

namespace lodforge {

const char* streamingName(Streaming mode) {
  switch (mode) {
    case Streaming::kCpu:
      return "cpu";
    case Streaming::kCpuGpuReform:
      return "cpu-stream-gpu-reform";
    case Streaming::kGpu:
      return "gpu";
  }
  return "?";
}

struct FramePipeline::State {
  Streaming mode = Streaming::kCpu;
  bool switchable = false;
  std::optional<StreamBuffer> cpu;
  std::optional<GpuStream> gpu;
  std::optional<GpuReformer> reformer;
  std::optional<Renderer> renderer;
  PipelineTimings timings;
};

namespace {

double millisecondsSince(std::chrono::steady_clock::time_point& start) {
  glFinish();  // the GPU's share of the step, not just issuing it
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - start).count();
  start = now;
  return ms;
}

}  // namespace

Result<FramePipeline> FramePipeline::create(const Package& package, const StreamCapacity& capacity,
                                            Streaming mode, bool switchable) {
  auto s = std::make_unique<State>();
  s->mode = mode;
  s->switchable = switchable;
  // The GPU arrangement draws from the stream's own buffers: no second copy.
  auto renderer = Renderer::create(package, capacity, switchable || mode != Streaming::kGpu);
  if (!renderer) return renderer.status();
  s->renderer.emplace(std::move(*renderer));
  if (switchable || mode != Streaming::kGpu) s->cpu.emplace(package, capacity);
  if (switchable || mode == Streaming::kGpu) {
    auto gpu = GpuStream::create(package, capacity);
    if (!gpu) return gpu.status();
    s->gpu.emplace(std::move(*gpu));
  }
  if (switchable || mode != Streaming::kCpu) {
    auto reformer = GpuReformer::create(package, capacity);
    if (!reformer) return reformer.status();
    s->reformer.emplace(std::move(*reformer));
  }
  return FramePipeline(std::move(s));
}

FramePipeline::FramePipeline(std::unique_ptr<State> state) : state_(std::move(state)) {}
FramePipeline::FramePipeline(FramePipeline&&) noexcept = default;
FramePipeline& FramePipeline::operator=(FramePipeline&&) noexcept = default;
FramePipeline::~FramePipeline() = default;

void FramePipeline::setStreaming(Streaming mode) {
  assert(state_->switchable || mode == state_->mode);
  state_->mode = mode;
}

Streaming FramePipeline::streaming() const {
  return state_->mode;
}
const PipelineTimings& FramePipeline::timings() const {
  return state_->timings;
}

Result<FrameStats> FramePipeline::update(std::span<const std::uint32_t> vertexCounts,
                                         std::span<const std::uint32_t> triangleCounts) {
  State& s = *state_;
  s.timings = {};
  auto start = std::chrono::steady_clock::now();
  if (s.mode == Streaming::kGpu) {
    auto stats = s.gpu->update(vertexCounts, triangleCounts);
    if (!stats) return stats.status();
    s.timings.streamMs = millisecondsSince(start);
    s.renderer->attach(*s.gpu);
    s.reformer->reform(*s.gpu, s.renderer->indexBuffer());
    s.timings.reformMs = millisecondsSince(start);
    return stats;
  }
  auto stats = s.cpu->update(vertexCounts, triangleCounts);
  if (!stats) return stats.status();
  s.timings.streamMs = millisecondsSince(start);
  const bool gpuReform = s.mode == Streaming::kCpuGpuReform;
  s.renderer->upload(*s.cpu, !gpuReform);
  s.timings.uploadMs = millisecondsSince(start);
  s.timings.uploadedBytes = s.renderer->uploadedBytes();
  if (gpuReform) {
    s.reformer->reform(*s.cpu, s.renderer->indexBuffer());
    s.timings.reformMs = millisecondsSince(start);
    s.timings.uploadedBytes += s.reformer->uploadedBytes();
  }
  return stats;
}

void FramePipeline::draw(const Camera& camera, const DrawOptions& options) {
  auto start = std::chrono::steady_clock::now();
  state_->renderer->draw(camera, options);
  state_->timings.drawMs = millisecondsSince(start);
}

}  // namespace lodforge
