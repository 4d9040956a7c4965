// Point-to-triangle distance and the surface distance between two meshes, measured by sampling:
// the quality measure for simplification and tiling (symmetric Hausdorff and RMS distance).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>

#include "lodforge/core/math.h"

namespace lodforge {

// Squared distance from p to triangle abc (closest point by Voronoi regions, Ericson §5.1.5).
double pointTriangleDistanceSquared(Vec3d p, Vec3d a, Vec3d b, Vec3d c);
// The closest point of triangle abc to p as weights of a, b and c (summing to 1).
Vec3d closestPointWeights(Vec3d p, Vec3d a, Vec3d b, Vec3d c);

struct SurfaceDistance {
  double hausdorff = 0;  // max over both directions of the max sample distance
  double rms = 0;        // root mean square over all samples of both directions
  double meanAB = 0, meanBA = 0;
  double maxAB = 0, maxBA = 0;  // each direction's largest: hausdorff is the larger
  // Where each direction's largest is: the sample of A farthest from B, of B farthest from A.
  Vec3d farthestOnA, farthestOnB;
};

namespace detail {
class TriangleGrid;
}

// The nearest triangle of one mesh to any point: the uniform grid surfaceDistance searches.
// The mesh's arrays must outlive it.
class NearestTriangles {
 public:
  NearestTriangles(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices);
  ~NearestTriangles();
  NearestTriangles(const NearestTriangles&) = delete;
  NearestTriangles& operator=(const NearestTriangles&) = delete;
  // The squared distance from p to the mesh (which must have a triangle); the nearest triangle
  // goes to `triangle`.
  double nearestSquared(Vec3d p, std::uint32_t& triangle) const;

 private:
  std::unique_ptr<detail::TriangleGrid> grid_;
};

// Distance between surfaces A and B: `samplesPerMesh` points spread over each surface by area
// (deterministic for the seed) plus, with `corners`, a corner of every triangle, each measured
// exactly to the nearest triangle of the other mesh through a uniform grid. Both meshes are
// plain arrays of positions and triangle indices.
SurfaceDistance surfaceDistance(std::span<const Vec3f> positionsA,
                                std::span<const std::uint32_t> indicesA,
                                std::span<const Vec3f> positionsB,
                                std::span<const std::uint32_t> indicesB,
                                std::uint32_t samplesPerMesh = 100'000, std::uint64_t seed = 1,
                                bool corners = true);

// surfaceDistance's Hausdorff distance alone (the same samples and value), faster: a sample's
// search ends as soon as it cannot exceed the largest distance found so far.
double sampledHausdorff(std::span<const Vec3f> positionsA, std::span<const std::uint32_t> indicesA,
                        std::span<const Vec3f> positionsB, std::span<const std::uint32_t> indicesB,
                        std::uint32_t samplesPerMesh = 100'000, std::uint64_t seed = 1,
                        bool corners = true);

// The largest exact distance from any of `points` to the surface (one-sided; infinity when the
// surface has no triangles).
double farthestDistance(std::span<const Vec3f> points, std::span<const Vec3f> positions,
                        std::span<const std::uint32_t> indices);

// A textured mesh for textureDistance: per-vertex texture coordinates, each triangle's texture
// (~0u: none) and each texture's size in texels (width, height).
struct TexturedSurface {
  std::span<const Vec3f> positions;
  std::span<const std::uint32_t> indices;
  std::span<const Vec2f> uvs;
  std::span<const std::uint32_t> texture;
  std::span<const std::array<std::uint32_t, 2>> texels;
};

struct TextureDistance {
  double mean = 0, median = 0, p95 = 0, max = 0;  // texels of A's textures
  std::uint64_t samples = 0;       // measured: B's nearest point has the same texture
  std::uint64_t otherTexture = 0;  // not measured: B has another texture (or none) there
};

// How far B's texture mapping is from A's, in texels: `samples` points spread over A's textured
// triangles by area, each with A's texture coordinate there, against B's coordinate at the
// closest point of B (the texture-space error of a simplification B of A). Textures are numbered
// alike in both.
TextureDistance textureDistance(const TexturedSurface& a, const TexturedSurface& b,
                                std::uint32_t samples = 100'000, std::uint64_t seed = 1);

}  // namespace lodforge
