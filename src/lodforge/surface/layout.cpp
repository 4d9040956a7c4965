#include "lodforge/surface/layout.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <fmt/format.h>

namespace lodforge {

ChunkBox ChunkLayout::reach(const Vec3d& p, double radius) const {
  assert(radius >= 0);
  ChunkBox box;
  const std::uint64_t size = n;
  const std::array<std::int64_t, 3> cell = pointCellOf(grid, p);
  for (std::size_t a = 0; a < 3; ++a) {
    // The cell's extent along the axis, in voxels.
    const double low = static_cast<double>(cell[a]) / kCellSplit;
    const double high = static_cast<double>(cell[a] + 1) / kCellSplit;
    const auto first = static_cast<std::uint64_t>(std::max(0.0, std::ceil(low - radius)));
    const auto last = static_cast<std::uint64_t>(std::max(0.0, std::floor(high + radius)));
    // Corner x lies in chunks ceil(x / n) − 1 … floor(x / n).
    box.lo[a] = std::min(chunks[a] - 1, first == 0 ? 0 : (first + size - 1) / size - 1);
    box.hi[a] = std::min(chunks[a] - 1, last / size);
  }
  return box;
}

std::uint64_t ChunkLayout::owner(const Vec3d& p) const {
  std::array<std::uint64_t, 3> at{};
  for (std::size_t a = 0; a < 3; ++a) {
    const double g = (p[static_cast<int>(a)] - grid.origin[static_cast<int>(a)]) / grid.voxel;
    at[a] = std::min(chunks[a] - 1, static_cast<std::uint64_t>(std::max(0.0, g)) / n);
  }
  return chunkIndex(at[0], at[1], at[2]);
}

namespace {

// A lattice edge's lower corner and its direction bits.
std::array<std::uint64_t, 3> edgeCorner(std::uint64_t key, const VoxelGrid& grid, int& direction) {
  // (Every edge query of the layout comes through here: a key names an edge of its lattice.)
  assert(key / 7 < grid.corners[0] * grid.corners[1] * grid.corners[2]);
  direction = static_cast<int>(key % 7) + 1;
  std::uint64_t corner = key / 7;
  std::array<std::uint64_t, 3> at{};
  for (std::size_t a = 0; a < 3; ++a) {
    at[a] = corner % grid.corners[a];
    corner /= grid.corners[a];
  }
  return at;
}

}  // namespace

bool ChunkLayout::onChunkFace(std::uint64_t key) const {
  int direction = 0;
  const std::array<std::uint64_t, 3> at = edgeCorner(key, grid, direction);
  for (std::size_t a = 0; a < 3; ++a)
    if ((direction & (1 << a)) == 0 && at[a] % n == 0) return true;
  return false;
}

std::array<std::int64_t, 3> ChunkLayout::chunkPlanesOf(std::uint64_t key) const {
  int direction = 0;
  const std::array<std::uint64_t, 3> at = edgeCorner(key, grid, direction);
  std::array<std::int64_t, 3> planes{-1, -1, -1};
  for (std::size_t a = 0; a < 3; ++a)
    if ((direction & (1 << a)) == 0 && at[a] % n == 0)
      planes[a] = static_cast<std::int64_t>(at[a] / n);
  return planes;
}

std::uint64_t ChunkLayout::lastChunkHolding(std::uint64_t key) const {
  int direction = 0;
  const std::array<std::uint64_t, 3> at = edgeCorner(key, grid, direction);
  std::array<std::uint64_t, 3> last{};
  // Along an axis the edge runs: the chunk of its lower corner; across: the highest chunk whose
  // corners include its coordinate (x / n; the last chunk where x is the lattice's end).
  for (std::size_t a = 0; a < 3; ++a) last[a] = std::min(chunks[a] - 1, at[a] / n);
  (void)direction;
  return chunkIndex(last[0], last[1], last[2]);
}

Status checkSurfaceExtent(std::uint64_t points, const Aabbd& bounds, const std::string& name) {
  if (points < 4)
    return badInput(name, fmt::format("{} points are too few for a surface: it takes at least 4, "
                                      "and enough to cover the surface at the voxel size",
                                      points));
  int spread = 0;
  for (int a = 0; a < 3; ++a) spread += bounds.max[a] > bounds.min[a] ? 1 : 0;
  if (spread < 2)
    return badInput(name,
                    "all points lie on a line or at one position: a surface needs points "
                    "spread in two directions at least");
  return {};
}

Status checkVoxelFits(const Aabbd& bounds, double voxel, double unitScale,
                      const std::string& name) {
  assert(unitScale > 0);
  const Vec3d size = bounds.max - bounds.min;
  const double longest = std::max({size.x, size.y, size.z});
  if (voxel <= longest / 4) return {};
  const auto units = [&](double v) { return v / unitScale; };
  return Error{ErrorKind::kUsage,
               fmt::format("{}: --voxel {:g} is more than a quarter of the cloud, which is "
                           "{:.4g} × {:.4g} × {:.4g}: a surface needs voxels across it; give "
                           "--voxel {:.4g} or less, or leave it out (twice the points' median "
                           "spacing)",
                           name, units(voxel), units(size.x), units(size.y), units(size.z),
                           units(longest / 4))};
}

Result<ChunkLayout> layOutChunks(const Aabbd& bounds, double voxel, std::uint32_t chunkVoxels,
                                 double radius, const std::string& name) {
  assert(!bounds.empty() && radius >= 0);
  if (!(voxel > 0) || !std::isfinite(voxel))
    return badInput(name, "the points have no spacing to size voxels by: give --voxel");
  ChunkLayout layout;
  layout.n = std::max<std::uint32_t>(2, chunkVoxels);
  const auto margin = static_cast<std::uint64_t>(std::ceil(radius)) + 1;
  layout.grid.voxel = voxel;
  double corners = 1;
  for (int a = 0; a < 3; ++a) {
    layout.grid.origin[a] = bounds.min[a] - static_cast<double>(margin) * voxel;
    const double along =
        std::ceil((bounds.max[a] - bounds.min[a]) / voxel) + 2.0 * static_cast<double>(margin) + 1;
    corners *= along;
    layout.grid.corners[static_cast<std::size_t>(a)] = static_cast<std::uint64_t>(along);
  }
  // Edge names count corners × 7 in 64 bits; far below that, the mesh would not fit anywhere.
  if (corners > 1e15)
    return Error{ErrorKind::kUsage,
                 fmt::format("{}: voxel {:g} is too small for a cloud {:g} across ({:.3g} grid "
                             "corners); try --voxel {:g} or larger",
                             name, voxel, length(bounds.max - bounds.min), corners,
                             length(bounds.max - bounds.min) / 10'000)};
  for (std::size_t a = 0; a < 3; ++a)
    layout.chunks[a] =
        std::max<std::uint64_t>(1, (layout.grid.corners[a] - 1 + layout.n - 1) / layout.n);
  return layout;
}

}  // namespace lodforge
