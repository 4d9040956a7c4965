// Meshes out of a package: every object at a chosen vertex count, re-formed (Algorithm 2) into
// an ordinary Model that any writer can save (`lodforge extract`).
#pragma once

#include <cstdint>
#include <span>

#include "lodforge/core/model.h"
#include "lodforge/simplify/package.h"

namespace lodforge {

// The vertex count per object for a uniform ratio of its full vertex count, clamped to [q, p]
// (rounded down to a whole count in a textured package).
std::vector<std::uint32_t> vertexCountsForRatio(const Package& package, double ratio);
// The fewest vertices per object whose recorded error is at most `error` (model units).
std::vector<std::uint32_t> vertexCountsForError(const Package& package, double error);

// Every object at vertexCounts[object] (a whole count, Package::wholeAt): its first n vertices
// and its re-formed first map(n) triangles. Objects keep their names, assembly paths and materials;
// the model takes the package's origin.
Model extractModel(const Package& package, std::span<const std::uint32_t> vertexCounts);

}  // namespace lodforge
