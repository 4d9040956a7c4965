// Tessellated CAD shapes for the assembly generator, built the way CAD exporters tessellate:
// flat faces get their own vertices (split along creases), curved faces share smooth normals,
// sheets are open. All shapes are outward-facing with counter-clockwise triangles.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "lodforge/core/math.h"

namespace lodforge {

struct PartMesh {
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;
  std::vector<std::uint32_t> indices;

  void clear() {
    positions.clear();
    normals.clear();
    indices.clear();
  }
  std::uint32_t vertex(Vec3f p, Vec3f n) {
    positions.push_back(p);
    normals.push_back(n);
    return static_cast<std::uint32_t>(positions.size() - 1);
  }
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    indices.insert(indices.end(), {a, b, c});
  }
  void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    triangle(a, b, c);
    triangle(a, c, d);
  }
};

// Box centred at the origin, each face an n x n grid.
void addBox(PartMesh& mesh, Vec3f size, int subdivisions);
// Smooth cylinder side around z from z0 to z1; normals point out (or in, for a bore).
void addCylinderSide(PartMesh& mesh, float radius, float z0, float z1, int segments, int rings,
                     bool outward);
// Flat disk at height z facing +z (up) or -z.
void addDisk(PartMesh& mesh, float radius, float z, int segments, bool up);
// Flat ring between two radii at height z facing +z (up) or -z.
void addAnnulus(PartMesh& mesh, float inner, float outer, float z, int segments, bool up);
// Prism over a simple counter-clockwise polygon, along z from 0 to length, with `segments`
// slices; flat-shaded sides, ear-clipped caps.
void addExtrusion(PartMesh& mesh, std::span<const Vec2f> profile, float length, int segments);
// A single-sided sheet in the z = 0 plane facing +z: columns x rows square cells, each with a
// round hole of `holeRadius` (relative to the cell, < 0.5) tessellated with `holeSegments`
// (a multiple of 8). Neighbouring cells share their edge vertices exactly.
void addPerforatedPlate(PartMesh& mesh, int columns, int rows, float cell, float holeRadius,
                        int holeSegments);

// Ear-clipping triangulation of a simple counter-clockwise polygon: writes n - 2 triangles
// (indices into the polygon) and returns false if the polygon is not simple enough to clip.
bool triangulatePolygon(std::span<const Vec2f> polygon, std::vector<std::uint32_t>& triangles);

}  // namespace lodforge
