// Merging border vertices (large-meshes paper §3.3): the duplicates that cutting made, and the
// children's shared borders in a parent, joined by exact position. Our cuts make border vertices
// bit-identical (chunk_grid.h), so no radius search is needed.
#pragma once

#include "lodforge/tiling/mesh_part.h"

namespace lodforge {

// Welds bit-identical positions of one object (cut vertices are made identical on purpose),
// drops triangles that repeat a corner and vertices no triangle uses. The first vertex of a
// group keeps its colour; the group's distinct normals are averaged (each once, so the result does
// not depend on how often a vertex was stored). Features that are all kNoFeature are dropped.
// Deterministic.
void weldExact(MeshPart& mesh);

}  // namespace lodforge
