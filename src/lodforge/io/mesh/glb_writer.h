// GLB (binary glTF 2.0) writer. GlbWriter streams: meshes go to the binary chunk as they are
// added (spilling to a temporary file past a threshold), nodes and materials are collected as
// JSON, and finish() assembles header + JSON + BIN under a temporary name and renames it. Output
// passes the Khronos glTF validator: accessor min/max on positions, unit normals, 4-byte
// aligned views, no primitive-restart index values.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "lodforge/core/material.h"
#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

// A vertex attribute of the application's own: scalar, one element per vertex, each padded to 4
// bytes (glTF aligns vertex attribute elements to 4 bytes).
struct GlbVertexAttribute {
  std::string semantic;  // begins with an underscore: "_CLASSIFICATION"
  int componentType =
      0;  // glTF's: 5120 BYTE, 5121 UNSIGNED_BYTE, 5122 SHORT, 5123 UNSIGNED_SHORT, 5126 FLOAT
  std::span<const std::byte> data;  // 4 bytes per vertex
};

struct GlbFeatureIds {
  std::uint32_t featureCount = 0;  // distinct features the attribute holds (0..count-1)
  std::uint32_t propertyTable = 0;
};

// A primitive of a mesh: the next `indexCount` indices, drawn with `material`.
struct GlbPrimitive {
  std::uint32_t indexCount = 0;
  std::optional<std::uint32_t> material;
};

struct GlbMeshData {
  std::span<const Vec3f> positions;
  std::span<const Vec3f> normals;          // empty or one per vertex (normalised on write)
  std::span<const Rgba8> colors;           // empty or one per vertex
  std::span<const std::uint32_t> indices;  // 3 per triangle, < positions.size(); none for points
  // KHR_mesh_quantization: positions as 16-bit integers on a grid over the mesh's box (the node
  // drawing it scales them back; error at most half a step, glbQuantizationStep), normals as
  // normalised 8-bit integers. A required extension.
  bool quantized = false;
  // A point cloud: one POINTS primitive over the vertices (glTF mode 0), no indices.
  bool points = false;
  std::span<const GlbVertexAttribute> extraAttributes = {};
  // EXT_structural_metadata: the property attribute (of setStructuralMetadata's) that describes
  // the extra attributes.
  std::optional<std::uint32_t> propertyAttribute = std::nullopt;
  // EXT_mesh_features: the extra attribute "_FEATURE_ID_0" holds each vertex's feature, a row
  // of this property table (of setStructuralMetadata's).
  std::optional<GlbFeatureIds> featureIds = std::nullopt;
  // Empty: one primitive with addMesh's material. Otherwise the indices in groups, one primitive
  // each, all over the same vertex attributes (a tile's parts grouped by material).
  std::span<const GlbPrimitive> primitives = {};
  std::span<const Vec2f> uvs = {};  // empty or one per vertex: TEXCOORD_0
  // Instead of `normals`, for a quantised mesh: normals packed already (glbPackNormal).
  std::span<const std::array<std::int8_t, 4>> packedNormals = {};
};

// A normal as a quantised mesh holds it: normalised, each axis × 127 rounded, then a zero byte.
std::array<std::int8_t, 4> glbPackNormal(Vec3f normal);

// The grid step of a quantised mesh inside `bounds`: its longest side over 65535.
double glbQuantizationStep(const Aabbd& bounds);
// The farthest a quantised position inside `bounds` moves: half a step on each axis, √3/2 of a
// step; 0 for a box without extent (its one position is the grid's origin, kept exactly).
double glbQuantizationError(const Aabbd& bounds);

struct GlbWriteOptions {
  // The default material (objects without one of their own) draws both sides: a PLY, OBJ or
  // STL mesh may well be an open sheet. The model's own materials keep their doubleSided.
  bool doubleSided = true;
  // Binary data beyond this stays on disk until finish() instead of in memory.
  std::size_t spillBytes = std::size_t{64} << 20;
  // EXT_meshopt_compression: vertex and index data encoded with meshoptimizer's codecs (a
  // required extension: viewers without it cannot read the file).
  bool meshoptCompression = false;
  // The nodes straight in the scene, without the root node that holds them (point tiles: a node
  // without a mesh trips three.js's EXT_structural_metadata loader in 3d-tiles-renderer 0.4);
  // setRootTranslation is then not used, and addNode's translation-only transforms stay
  // translations.
  bool flatScene = false;
  // writeGlb: an object that is an earlier object's mesh moved rigidly (a CAD shape placed
  // again, a glTF mesh under several nodes) is written as that mesh under a node transform
  // (findPlacements, core/instances.h).
  bool shareMeshes = true;
};

class GlbWriter {
 public:
  static Result<GlbWriter> create(const std::string& path, const GlbWriteOptions& options = {});
  GlbWriter(GlbWriter&&) noexcept;
  GlbWriter& operator=(GlbWriter&&) noexcept;
  ~GlbWriter();

  // A material with this base colour (linear RGBA); index for addMesh.
  std::uint32_t addMaterial(const std::array<float, 4>& baseColor, std::string_view name = {});
  // A material as the input described it, drawing `texture` (addTexture's) as its base colour
  // at TEXCOORD_0 when given (its baseColorImage is not looked at).
  std::uint32_t addMaterial(const Material& material,
                            std::optional<std::uint32_t> texture = std::nullopt);
  // An encoded image (JPEG, PNG or WebP: EXT_texture_webp, required) in the binary chunk with a
  // sampler of these wrap modes (linear filtering, mipmaps); returns the texture's index.
  Result<std::uint32_t> addTexture(std::span<const std::byte> encoded, ImageFormat format,
                                   TextureWrap wrapS = TextureWrap::kRepeat,
                                   TextureWrap wrapT = TextureWrap::kRepeat);
  // Writes the mesh's data; returns its mesh index for addNode. Empty meshes are refused (assert).
  Result<std::uint32_t> addMesh(const GlbMeshData& mesh, std::string_view name = {},
                                std::optional<std::uint32_t> material = std::nullopt);
  // The document's EXT_structural_metadata object (schema, property tables and attributes), as
  // JSON.
  void setStructuralMetadata(std::string json);
  // A buffer view of raw bytes, 8-byte aligned (a property table's values or string offsets);
  // returns its index.
  Result<std::uint32_t> addBufferView(std::span<const std::byte> bytes);
  // A node drawing `mesh` (or nothing) with an optional transform, a child of `parent` (a node
  // added before) or of the root node; returns its index. A CAD `layer` goes to its extras.
  std::uint32_t addNode(std::string_view name, std::optional<std::uint32_t> mesh,
                        const Mat4d* transform = nullptr,
                        std::optional<std::uint32_t> parent = std::nullopt,
                        std::string_view layer = {});
  // Translation of the root node: places float geometry at a double-precision origin.
  void setRootTranslation(Vec3d translation);
  // The root node's name ("root" unless set).
  void setRootName(std::string_view name);
  // Size of the binary chunk so far (GLB caps a file at 4 GiB).
  std::uint64_t binaryBytes() const;
  Status finish();

 private:
  struct State;
  explicit GlbWriter(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

// Writes a whole Model: one node per object with its mesh, or an earlier object's mesh under a
// matrix when it repeats it (findPlacements; objects without triangles become empty nodes), the
// origin as the root translation. Objects with an assembly path hang in the node tree the path
// names ("motor/rotor/shaft": nodes "motor" and "rotor" above the object's node "shaft"), one node
// per distinct prefix; a first component all paths share names the root node instead, so a GLB read
// and written again keeps its tree.
Status writeGlb(const Model& model, const std::string& path, const GlbWriteOptions& options = {});

}  // namespace lodforge
