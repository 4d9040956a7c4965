// A chunk's piece thinned before it is joined: marching tetrahedra make about twice the triangles
// marching cubes would, most of them on nearly flat surface. Edge collapses (simplify/progressive)
// within an error bound, every vertex on a chunk face locked, so that the join by vertex name
// stays exact and crack-free whatever each chunk removed.
#pragma once

#include "lodforge/surface/layout.h"
#include "lodforge/surface/marching_tetrahedra.h"

namespace lodforge {

// The piece with collapses whose vertex error bound stays within `maxError` (model units; 0 or
// less: the piece as it is). Kept vertices keep their position, normal, colour and edge name; a
// rim of the surface (an open edge of the scan) and the chunk-face vertices stay.
SurfacePiece decimatePiece(const ChunkLayout& layout, SurfacePiece piece, double maxError);

}  // namespace lodforge
