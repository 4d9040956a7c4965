// Objects one at a time, for builders that must not hold a whole assembly in memory. A binary
// or ascii PLY whose faces carry object ids grouped by object (faces of one object together,
// ids increasing, each object's vertices in their own range — what `generate cad` and the PLY
// writer produce) is streamed with two cursors, one in the vertex section and one in the face
// section. Anything else is loaded as a Model and handed out object by object.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"
#include "lodforge/io/model_io.h"

namespace lodforge {

struct SourceObject {
  std::string name;
  std::string path;                      // in the assembly; empty without a tree
  std::uint32_t material = kNoMaterial;  // into the stream's materials()
  std::uint32_t layer = kNoLayer;        // into the stream's layers()
  std::vector<Vec3f> positions;          // relative to the stream's origin
  std::vector<Vec3f> normals;            // empty or one per vertex
  std::vector<Rgba8> colors;             // empty or one per vertex
  std::vector<Vec2f> uvs;                // empty or one per vertex (a textured material's)
  std::vector<std::uint32_t> indices;    // local

  std::uint64_t memoryBytes() const {
    return positions.size() * 12 + normals.size() * 12 + colors.size() * 4 + uvs.size() * 8 +
           indices.size() * 4 + name.size() + path.size();
  }
};

class ObjectStream {
 public:
  virtual ~ObjectStream() = default;
  // The next object; false at the end. A grouped-PLY stream that meets ungrouped faces returns
  // ErrorKind::kUnsupported: reopen with `load` set to read the whole model instead.
  virtual Result<bool> next(SourceObject& object) = 0;
  virtual Vec3d origin() const = 0;
  virtual bool hasNormals() const = 0;
  virtual bool hasColors() const = 0;
  virtual bool streaming() const = 0;
  virtual std::uint64_t triangleCountHint() const = 0;  // for progress; faces for PLY
  // What the objects' material indices refer to (empty for a grouped PLY).
  virtual std::span<const Material> materials() const { return {}; }
  // What the objects' layer indices refer to (CAD layers; empty for a grouped PLY).
  virtual std::span<const std::string> layers() const { return {}; }
  // What the materials' textures refer to (Material::baseColorImage), still encoded.
  virtual std::span<const ImageSource> images() const { return {}; }
};

struct ObjectStreamOptions {
  ReadOptions read;
  bool load = false;  // never stream: load the model first
};

Result<std::unique_ptr<ObjectStream>> openObjectStream(const std::string& path,
                                                       const ObjectStreamOptions& options = {});

}  // namespace lodforge
