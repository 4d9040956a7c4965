// Repeated meshes in a model of world positions: objects that are one mesh placed again (a CAD
// shape placed many times, a glTF mesh under several nodes) are found again so a GLB writes the
// mesh once and places it with a node transform, and `lodforge build` simplifies it once.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "lodforge/core/math.h"
#include "lodforge/core/model.h"

namespace lodforge {

// How far a placed vertex may lie from the moved source, relative to the mesh's size: loose
// enough for a writer's float rounding, far below anything a viewer shows.
inline constexpr double kPlacementTolerance = 1e-5;

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

// One object's mesh as placements compare it; normals and colours empty when there are none.
struct MeshView {
  std::span<const Vec3f> positions, normals;
  std::span<const Rgba8> colors;
  std::span<const std::uint32_t> indices;  // local
  std::uint32_t material = kNoMaterial;
  std::span<const Vec2f> uvs = {};  // a placement keeps its texture coordinates exactly
};

// What a search for a mesh's placement needs: what two placements of one mesh share exactly
// (counts, material, triangles, colours, UVs) hashed, its spread (the RMS distance of its vertices
// from their centroid, which a rigid motion keeps), and how far a placed vertex may lie from the
// moved source (`relativeTolerance` of the mesh's size, never less than float rounding at its
// distance from the origin).
struct PlacementKey {
  std::uint64_t signature = 0;
  double spread = 0, tolerance = 0;
  // Finite, and not so near a line that the turn about it is undetermined: a fit can succeed.
  bool fittable = false;
};
PlacementKey placementKey(const MeshView& mesh, double relativeTolerance);

// The motion that places `source` as `mesh`: same triangles, colours and material, every vertex
// within `tolerance` after the motion, normals within 1e-3 (the fronts follow, the motion being
// proper and the indices equal); none otherwise.
std::optional<Mat4d> placementOf(const MeshView& source, const MeshView& mesh, double tolerance);

struct FoundPlacement {
  std::uint32_t source = 0;
  Mat4d motion;
};

// Meshes kept to place others from, by signature and spread: a search fits only kept meshes whose
// spread is within twice the larger of the two tolerances, nearest spread first, at most
// `candidates` of them.
class PlacementIndex {
 public:
  explicit PlacementIndex(std::size_t candidates = 64) : candidates_(candidates) {}
  // A kept mesh that `mesh` is a placement of (the nearest in spread that fits); `kept` gives a
  // kept mesh by its id.
  std::optional<FoundPlacement> find(const PlacementKey& key, const MeshView& mesh,
                                     const std::function<MeshView(std::uint32_t)>& kept) const;
  // Keeps mesh `id`; false when it cannot be fitted or as many meshes like it are kept already.
  bool add(const PlacementKey& key, std::uint32_t id);

 private:
  struct Kept {
    std::multimap<double, std::pair<std::uint32_t, double>> bySpread;  // → (id, tolerance)
    double widest = 0;  // the largest tolerance kept: how far a search must look
  };
  std::size_t candidates_;
  std::unordered_map<std::uint64_t, Kept> meshes_;  // by signature
};

// One placement per object. An object is placed from an earlier one when both have the same
// triangles (indices), colours and material, and a rigid motion takes the earlier's vertices
// onto its own (placementOf, within its key's tolerance), found through a PlacementIndex.
std::vector<Placement> findPlacements(const Model& model,
                                      double relativeTolerance = kPlacementTolerance,
                                      std::size_t candidates = 64);

}  // namespace lodforge
