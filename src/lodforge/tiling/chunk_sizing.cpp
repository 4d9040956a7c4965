#include "lodforge/tiling/chunk_sizing.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace lodforge {

namespace {
constexpr std::uint64_t kLeastLeafTriangles = 2048;
constexpr std::uint64_t kLeastLevelTriangles = 16;
}  // namespace

std::uint64_t leafTriangles(const ChunkInputOptions& options, std::uint64_t triangles) {
  return std::min(options.trianglesPerChunk, std::max(triangles / 16, kLeastLeafTriangles));
}

Result<double> chunkSizeFor(const ChunkInputOptions& options, const Aabbd& bounds,
                            std::uint64_t triangles) {
  if (options.chunkSize > 0) return options.chunkSize;
  double size = ChunkGrid::sizeFor(bounds, triangles, leafTriangles(options, triangles));
  if (options.levels <= 0) return size;
  int most = 0;
  while (most < 30 && (triangles >> (2 * (most + 1))) >= kLeastLevelTriangles) ++most;
  if (options.levels > most)
    return Error{ErrorKind::kUsage,
                 fmt::format("--levels {}: the model's {} triangles make at most {} levels above "
                             "the leaves (each level quarters a surface's leaves, and a leaf "
                             "keeps at least {} triangles)",
                             options.levels, triangles, most, kLeastLevelTriangles)};
  return std::min(size, std::max(bounds.longestSide(), 1e-9) / std::ldexp(1.0, options.levels));
}

Vec3f transformNormal(const ChunkInputOptions& options, Vec3d in, Vec3d out, Vec3f normal) {
  Vec3d ahead;
  if (!options.transform || !options.transform(in + toDouble(normal), ahead)) return normal;
  return normalizeOr(toFloat(ahead - out), normal);
}

}  // namespace lodforge
