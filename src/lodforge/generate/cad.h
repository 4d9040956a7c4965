// `lodforge generate cad`: a CAD-like assembly in the spirit of the CAD paper's Boeing 777 — many
// separate parts of widely varying size and tessellation (bolts, tubes, boxes, brackets, plates
// with holes, long beams and rods) placed through a fuselage-and-wings volume. Parts are
// tessellated the way CAD exporters do it (vertices split along creases, open sheets).
//
// Output by extension: GLB (one node per part, standard bolts instanced from a catalogue, one
// material per finish) for moderate sizes; binary PLY with a per-face object_id for any size,
// streamed in two passes (count, then write) with memory independent of the part count.
#pragma once

#include <cstdint>
#include <string>

#include "lodforge/core/status.h"
#include "lodforge/generate/stats.h"

namespace lodforge {

struct CadOptions {
  std::uint64_t objects = 10'000;
  std::uint64_t seed = 1;
  double detail = 1.0;  // multiplies tessellation density (segments, rings, subdivisions)
};

Result<GenerateStats> generateCad(const CadOptions& options, const std::string& path);

}  // namespace lodforge
