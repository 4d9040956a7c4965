// A model simplified to a share of its triangles, object by object (`convert --simplify`, as
// gltfpack -si does): each object's surface (its vertices welded by position) collapses with its
// attribute vertices carried as wedges (ProgressiveOptions::wedges), so texture seams and normal
// or colour splits slide along themselves and never open, no triangle takes coordinates from
// two charts, and the texture error is part of the cost; rims slide along themselves.
#pragma once

#include <cstdint>

#include "lodforge/core/model.h"

namespace lodforge {

struct ModelSimplifyStats {
  std::uint64_t trianglesBefore = 0, trianglesAfter = 0;
  double error = 0;  // the largest object's recorded error (model units, simplify.md)
};

// `ratio` in [0, 1]: the share of each object's triangles to keep (at least one; an object may
// keep more where no collapse is valid).
ModelSimplifyStats simplifyModel(Model& model, double ratio);

}  // namespace lodforge
