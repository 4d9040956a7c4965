// A model simplified to a share of its triangles, object by object (`convert --simplify`, as
// gltfpack -si does): each object's surface (its vertices welded by position) collapses with its
// attribute vertices carried as wedges (ProgressiveOptions::wedges), so texture seams and normal
// or colour splits slide along themselves and never open, no triangle takes coordinates from
// two charts, and the texture error is part of the cost; rims slide along themselves.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/model.h"

namespace lodforge {

// A mesh's triangles over its surface points, each corner naming its wedge (the mesh vertex it
// came from): what simplifyMesh takes with ProgressiveOptions::wedges. `pointOf` gives each
// mesh vertex's surface point; triangles with two corners at one point have no area and go.
struct WedgeSurface {
  std::vector<std::uint32_t> indices, wedges;
};
WedgeSurface wedgeSurface(std::span<const std::uint32_t> pointOf,
                          std::span<const std::uint32_t> indices);

struct ModelSimplifyStats {
  std::uint64_t trianglesBefore = 0, trianglesAfter = 0;
  double error = 0;  // the largest object's recorded error (model units, simplify.md)
};

// `ratio` in [0, 1]: the share of each object's triangles to keep (at least one; an object may
// keep more where no collapse is valid).
ModelSimplifyStats simplifyModel(Model& model, double ratio);

}  // namespace lodforge
