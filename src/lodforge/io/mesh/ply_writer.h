// Binary little-endian PLY writer. PlyWriter streams: the counts are declared up front, which
// fixes where the vertex and face sections start, so vertices and faces may be appended in any
// interleaving (object by object) and each section is filled in place. A generator writes files
// larger than RAM this way. The file appears under its name only when finish() succeeds.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/core/model.h"

namespace lodforge {

struct PlyLayout {
  std::uint64_t vertexCount = 0;
  std::uint64_t faceCount = 0;  // triangles; no face element when 0 (a point cloud)
  bool normals = false;
  bool colors = false;
  bool objectIds = false;  // an "object_id" uint property per face
  // MeshLab's textured faces: a "texcoord" list of 6 floats (OpenGL's way up, t = 1 - v) and a
  // "texnumber" int per face, into "comment TextureFile" lines the caller puts in `comments`.
  bool faceUvs = false;
  bool doublePositions = false;  // x y z as double (origin added back), for geo-scale models
  std::vector<std::string> comments{};
};

class PlyWriter {
 public:
  static Result<PlyWriter> create(const std::string& path, const PlyLayout& layout);

  // Positions are relative to `origin` (written as origin + p when doublePositions is set).
  // normals/colors must be given iff the layout has them.
  Status writeVertices(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                       std::span<const Rgba8> colors, Vec3d origin = {});
  // Global vertex indices, 3 per triangle; objectIds per triangle iff the layout has them;
  // cornerUvs (3 per triangle, glTF's way up) and textures (per triangle) iff it has faceUvs.
  Status writeTriangles(std::span<const std::uint32_t> indices,
                        std::span<const std::uint32_t> objectIds = {},
                        std::span<const Vec2f> cornerUvs = {},
                        std::span<const std::uint32_t> textures = {});
  // Checks that the declared counts were written, then renames the file into place.
  Status finish();
  std::uint64_t fileBytes() const { return faceStart_ + layout_.faceCount * faceStride(); }

 private:
  // One section of the file, filled front to back through its own buffer.
  struct Section {
    std::uint64_t cursor = 0;
    std::vector<std::byte> buffer;
  };
  PlyWriter(OutputFile file, PlyLayout layout, std::uint64_t vertexStart);
  std::size_t vertexStride() const;
  std::size_t faceStride() const {
    return 13u + (layout_.objectIds ? 4u : 0u) + (layout_.faceUvs ? 1u + 24u + 4u : 0u);
  }
  Status flush(Section& section);

  OutputFile file_;
  PlyLayout layout_;
  std::uint64_t faceStart_ = 0;
  Section vertices_, faces_;
  std::uint64_t verticesWritten_ = 0;
  std::uint64_t facesWritten_ = 0;
};

// Writes a whole Model: object ids per face when it has more than one object.
Status writePly(const Model& model, const std::string& path);

}  // namespace lodforge
