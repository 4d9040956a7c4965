// Repeated meshes in a model of world positions: objects that are one mesh placed again (a CAD
// shape placed many times, a glTF mesh under several nodes) are found again so a GLB writes the
// mesh once and places it with a node transform.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/model.h"

namespace lodforge {

// Where an object's triangles come from in the written file: its own mesh (source == the
// object, transform the identity) or an earlier object's, moved by `transform`.
struct Placement {
  std::uint32_t source = 0;
  Mat4d transform;
};

// The rigid motion (rotation and translation, no mirror, no scale) that takes `from` onto `to`
// vertex by vertex, each within `tolerance`; none if there is no such motion.
std::optional<Mat4d> fitRigidMotion(std::span<const Vec3f> from, std::span<const Vec3f> to,
                                    double tolerance);

// One placement per object. An object is placed from an earlier one when both have the same
// triangles (indices), colours and material, and a rigid motion takes the earlier's vertices
// onto its own within `relativeTolerance` of the object's size (normals within 1e-3; the fronts
// follow, the motion being proper and the indices equal). Only objects with the same signature
// (counts, material, triangles, colours) are compared, against at most `candidates` meshes each.
std::vector<Placement> findPlacements(const Model& model, double relativeTolerance = 1e-5,
                                      std::size_t candidates = 64);

}  // namespace lodforge
