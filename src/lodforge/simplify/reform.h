// Triangle reformation, Algorithm 2 of Peng & Cao: the mesh of an object at n vertices is its
// first map(n) rearranged triangles with every corner >= n replaced by following ECol until it
// is < n. The kernel runs data-parallel over triangles across all selected objects (each
// triangle finds its object by binary search over the selection's prefix sums, §3.2), so a
// few huge objects and many tiny ones keep every thread busy alike.
#pragma once

#include <cstdint>
#include <span>

#include "lodforge/simplify/package.h"

namespace lodforge {

// Algorithm 2 on one triangle corner: follow the decreasing chain below n.
inline std::uint32_t reformCorner(std::uint32_t corner, std::uint32_t n,
                                  const std::uint32_t* ecol) {
  while (corner >= n) corner = ecol[corner];
  return corner;
}

// One object: `triangles` are its first map(n) rearranged triangles (3 per triangle), `ecol`
// its ECol. Writes the re-formed triangles plus `vertexBase` into `out` (same size).
void reformObject(std::span<const std::uint32_t> triangles, std::span<const std::uint32_t> ecol,
                  std::uint32_t n, std::uint32_t vertexBase, std::span<std::uint32_t> out);

// Where the selected objects' data lives: all objects' triangles and ECols back to back, and the
// object table with each object's offsets into them (the package's sections, read in place).
struct ReformSource {
  std::span<const std::uint32_t> triangles;  // 3 per triangle, object-local corners
  std::span<const std::uint32_t> ecol;       // object-local
  std::span<const PackageObject> objects;

  static ReformSource of(const Package& package) {
    return {package.allTriangles(), package.allEcol(), package.objects()};
  }
};

struct ReformSelection {
  std::span<const std::uint32_t> objects;       // selected object ids
  std::span<const std::uint32_t> vertexCounts;  // n per selected object
  // Prefix sums of the selected triangle counts map(n): selection i writes triangles
  // [outputStart[i], outputStart[i + 1]); size objects.size() + 1.
  std::span<const std::uint64_t> outputStart;
  std::span<const std::uint32_t> vertexBase;  // added to every corner of selection i
};

// Writes 3 * outputStart.back() indices into `out`.
void reformSelection(const ReformSource& source, const ReformSelection& selection,
                     std::span<std::uint32_t> out);

}  // namespace lodforge
