// A textured PLY (MeshLab, OpenDroneMap): its "comment TextureFile NAME" lines as materials and
// images (texnumber i draws file i; one that is missing or unreadable is a warning and a grey
// material), and its triangles as a textured model: an object per texture (and object id),
// a vertex per distinct (vertex, texture coordinate) in each.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/model.h"
#include "lodforge/io/mesh/ply_header.h"

namespace lodforge {

// Whether the faces can be drawn textured: texture files, and texture coordinates per vertex
// or per face corner.
bool plyTextured(const PlyHeader& header);

struct PlyTextures {
  std::vector<Material> materials;  // one per texture file, in order
  std::vector<ImageSource> images;
};
PlyTextures readPlyTextures(const PlyHeader& header, const std::string& path,
                            std::vector<std::string>* warnings);

// What readPly gathered of a textured file: per vertex, per triangle, per triangle corner.
struct PlyTexturedData {
  std::span<const Vec3f> positions, normals;  // normals: empty or one per position
  std::span<const Rgba8> colors;              // empty or one per position
  std::span<const Vec2f> uvs;                 // per vertex, or empty (then cornerUvs)
  std::span<const std::uint32_t> triangles;
  std::span<const Vec2f> cornerUvs;                 // 3 per triangle, or empty
  std::span<const std::uint32_t> triangleTextures;  // per triangle, or empty (texture 0)
  std::span<const std::uint32_t> triangleObjects;   // per triangle, or empty
};
// Appends the objects to `model` (whose origin is set), with `textures` as its materials and
// images. A texnumber past the texture files is bad input naming it.
Status addTexturedPly(Model& model, const PlyTexturedData& data, PlyTextures textures,
                      const std::string& name);

}  // namespace lodforge
