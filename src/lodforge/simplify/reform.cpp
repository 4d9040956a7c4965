#include "lodforge/simplify/reform.h"

#include <algorithm>
#include <cassert>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace lodforge {

void reformObject(std::span<const std::uint32_t> triangles, std::span<const std::uint32_t> ecol,
                  std::uint32_t n, std::uint32_t vertexBase, std::span<std::uint32_t> out) {
  assert(out.size() == triangles.size());
  assert(n <= ecol.size());
  for (std::size_t i = 0; i < triangles.size(); ++i)
    out[i] = reformCorner(triangles[i], n, ecol.data()) + vertexBase;
}

void reformSelection(const ReformSource& source, const ReformSelection& selection,
                     std::span<std::uint32_t> out) {
  const std::size_t selected = selection.objects.size();
  assert(selection.vertexCounts.size() == selected && selection.vertexBase.size() == selected);
  assert(selection.outputStart.size() == selected + 1);
  const std::uint64_t total = selection.outputStart[selected];
  assert(out.size() >= 3 * total);
  tbb::parallel_for(
      tbb::blocked_range<std::uint64_t>(0, total, 2048),
      [&](const tbb::blocked_range<std::uint64_t>& range) {
        // The owning selection of the range's first triangle: binary search over the prefix sums.
        std::size_t s =
            static_cast<std::size_t>(std::upper_bound(selection.outputStart.begin(),
                                                      selection.outputStart.end(), range.begin()) -
                                     selection.outputStart.begin() - 1);
        for (std::uint64_t t = range.begin(); t < range.end(); ++t) {
          while (t >= selection.outputStart[s + 1]) ++s;  // later triangles walk on from there
          const std::uint32_t object = selection.objects[s];
          const std::uint32_t n = selection.vertexCounts[s];
          const PackageObject& record = source.objects[object];
          const std::uint32_t* ecol = source.ecol.data() + record.vertexOffset;
          const std::uint32_t* corners =
              source.triangles.data() +
              3 * (record.triangleOffset + (t - selection.outputStart[s]));
          for (std::size_t k = 0; k < 3; ++k)
            out[3 * t + k] = reformCorner(corners[k], n, ecol) + selection.vertexBase[s];
        }
      });
}

}  // namespace lodforge
