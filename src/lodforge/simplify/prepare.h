// Turns one object as read from a file into what buildProgressive expects: positions welded
// (CAD exports split vertices along creases; nothing collapses across a split), repeated-corner
// triangles dropped, unreferenced vertices dropped, one normal and one colour per position.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/math.h"

namespace lodforge {

struct PreparedObject {
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;  // empty when the input had none and none were asked for
  std::vector<Rgba8> colors;
  std::vector<std::uint32_t> indices;
};

struct PrepareOptions {
  // Normals per welded position: the average of the input normals that meet there, or, when
  // the input has none, area-weighted face normals. Off: keep the input's (possibly none).
  bool normals = true;
};

PreparedObject prepareObject(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                             std::span<const Rgba8> colors, std::span<const std::uint32_t> indices,
                             const PrepareOptions& options = {});

// A textured object as buildProgressive takes it with ProgressiveOptions::wedges: its surface
// (a point per position, triangles without a repeated point) with each corner's wedge, and the
// wedges (the input's vertices that differ in position, coordinates, normal or colour, unused
// ones dropped) with their attributes. Normals: the input's, or per point area-weighted and
// shared by its wedges, so shading stays smooth across a texture seam.
struct PreparedTexturedObject {
  std::vector<Vec3f> points;
  std::vector<std::uint32_t> indices;  // over points
  std::vector<std::uint32_t> wedges;   // per corner of `indices`
  std::vector<Vec2f> uvs;              // per wedge
  std::vector<Vec3f> normals;          // per wedge
  std::vector<Rgba8> colors;           // per wedge, or empty
};

PreparedTexturedObject prepareTexturedObject(std::span<const Vec3f> positions,
                                             std::span<const Vec3f> normals,
                                             std::span<const Rgba8> colors,
                                             std::span<const Vec2f> uvs,
                                             std::span<const std::uint32_t> indices);

}  // namespace lodforge
