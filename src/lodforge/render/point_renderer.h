// Draws a frame's point selection (runtime/gaze.h) as round splats: GL_POINTS sized by each
// node's radius projected at its depth (the paper's planar squares, drawn as discs facing the
// viewer), headlight-shaded with their normals on both sides.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "lodforge/core/status.h"
#include "lodforge/runtime/camera.h"
#include "lodforge/runtime/gaze.h"

namespace lodforge {

struct PointDrawOptions {
  std::array<std::uint8_t, 3> background = {40, 44, 52};
  float maxSplatPixels = 64;  // the largest disc drawn (a near splat would fill the screen)
};

class PointRenderer {
 public:
  // Needs a current GL 4.5 context.
  static Result<PointRenderer> create();
  PointRenderer(PointRenderer&&) noexcept;
  PointRenderer& operator=(PointRenderer&&) noexcept;
  ~PointRenderer();

  // Copies the selection's splats to the GL (buffers grow as needed).
  void upload(const PointSelection& selection);
  // Draws into the bound framebuffer (viewport = camera's size).
  void draw(const Camera& camera, const PointDrawOptions& options = {}) const;
  std::uint64_t uploadedBytes() const;

 private:
  struct State;
  explicit PointRenderer(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
