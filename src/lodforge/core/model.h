// The model in memory: a few flat arrays plus an object table. The same shape holds one scanned
// mesh or a CAD assembly of a million parts; there are no per-object vectors.
//
// Conventions:
// - positions are float, relative to a double-precision `origin` (world = origin + position), so
//   geo-scale coordinates keep millimetres.
// - triangle indices are local to their object: triangle t of object o refers to vertices
//   objects[o].vertexOffset + indices[3t + k].
// - normals, colors and uvs are either empty or one per vertex.
// - an object with a textured material (Material::baseColorImage) has that one material for all
//   its triangles: readers split a mesh whose parts use different textures into objects.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "lodforge/core/image_source.h"
#include "lodforge/core/material.h"
#include "lodforge/core/math.h"

namespace lodforge {

struct ObjectRecord {
  std::uint64_t vertexOffset = 0;
  std::uint64_t triangleOffset = 0;
  std::uint32_t vertexCount = 0;
  std::uint32_t triangleCount = 0;
  std::uint64_t nameOffset = 0;  // into Model::names
  std::uint32_t nameLength = 0;
  std::uint32_t layer = kNoLayer;  // into Model::layers (in the padding: the record stays 80 B)
  // Where the object sits in its assembly ("motor/rotor/shaft"), into Model::paths; empty when
  // the input has no assembly tree.
  std::uint64_t pathOffset = 0;
  std::uint32_t pathLength = 0;
  std::uint32_t material = kNoMaterial;  // into Model::materials
  Aabb bounds;                           // of the object's vertices, relative to the model origin
};
static_assert(sizeof(ObjectRecord) == 80);

struct Model {
  Vec3d origin;
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;          // empty or one per vertex
  std::vector<Rgba8> colors;           // empty or one per vertex
  std::vector<Vec2f> uvs;              // empty or one per vertex: the base-colour texture's
  std::vector<std::uint32_t> indices;  // 3 per triangle, local to the object
  std::vector<ObjectRecord> objects;
  std::string names;                // all object names, back to back
  std::string paths;                // all object assembly paths, back to back (often empty)
  std::vector<Material> materials;  // what objects refer to (few: a table, not per object)
  // CAD layers objects are on, by name ("fasteners", or "a; b" for an object on two): a table
  // like materials.
  std::vector<std::string> layers;
  std::vector<ImageSource> images;  // what materials' textures refer to, still encoded

  std::uint64_t vertexCount() const { return positions.size(); }
  std::uint64_t triangleCount() const { return indices.size() / 3; }
  std::uint64_t objectCount() const { return objects.size(); }
  bool hasNormals() const { return !normals.empty(); }
  bool hasColors() const { return !colors.empty(); }
  bool hasUvs() const { return !uvs.empty(); }

  std::string_view objectName(std::size_t object) const {
    const ObjectRecord& o = objects[object];
    return std::string_view(names).substr(o.nameOffset, o.nameLength);
  }
  std::string_view objectLayer(std::size_t object) const {
    const std::uint32_t layer = objects[object].layer;
    return layer < layers.size() ? std::string_view(layers[layer]) : std::string_view();
  }
  std::string_view objectPath(std::size_t object) const {
    const ObjectRecord& o = objects[object];
    return std::string_view(paths).substr(o.pathOffset, o.pathLength);
  }
  std::span<const Vec3f> objectPositions(std::size_t object) const {
    const ObjectRecord& o = objects[object];
    return std::span(positions).subspan(o.vertexOffset, o.vertexCount);
  }
  std::span<const std::uint32_t> objectIndices(std::size_t object) const {
    const ObjectRecord& o = objects[object];
    return std::span(indices).subspan(3 * o.triangleOffset, 3 * std::size_t{o.triangleCount});
  }
  Aabb bounds() const;
  // Bytes the arrays take, i.e. what loading the model costs.
  std::uint64_t memoryBytes() const;
};

// Bytes a model of these counts takes in memory (for `info` and memory limits before loading).
std::uint64_t modelMemoryBytes(std::uint64_t vertexCount, std::uint64_t triangleCount,
                               std::uint64_t objectCount, bool normals, bool colors,
                               std::uint64_t nameBytes = 0);

// Appends objects one at a time and keeps offsets, names and bounds consistent. Between
// beginObject and endObject the caller appends to the model's arrays directly (in bulk);
// endObject turns what was appended into the object's record. Empty objects are kept so object
// ids stay stable.
class ModelBuilder {
 public:
  explicit ModelBuilder(Model& model) : model_(model) {}

  void beginObject(std::string_view name, std::string_view path = {});
  // Appends a vertex to the current object; returns its local index.
  std::uint32_t addVertex(Vec3f position);
  void addTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c);
  // Closes the current object: counts from the arrays' growth, bounds from its positions.
  void endObject();

 private:
  Model& model_;
  bool open_ = false;
};

// Gives each distinct CAD layer name one index in a layer table (Model::layers): readers intern
// the names they meet through it. A map, not a search of the table: a file may give every part a
// layer of its own.
class LayerTable {
 public:
  explicit LayerTable(std::vector<std::string>& layers) : layers_(layers) {}
  // kNoLayer for an empty name.
  std::uint32_t index(const std::string& name);

 private:
  std::vector<std::string>& layers_;
  std::unordered_map<std::string, std::uint32_t> index_;
};

// Picks a double origin for world coordinates: zero for models near the origin, otherwise the
// box centre rounded to whole units so float offsets keep sub-millimetre precision.
Vec3d chooseOrigin(const Aabbd& worldBounds);
// The model's positions from world coordinates (one per position): the origin chosen for their
// bounds, each position relative to it, each object's bounds (readers that transform nodes).
void placeAtOrigin(Model& model, std::span<const Vec3d> world);

// Welds each object's vertices (see weldVertices) and drops the triangles that welding made
// degenerate (repeated corners). Objects stay separate: nothing welds across objects.
struct WeldOptions;
void weldModel(Model& model, const WeldOptions& options);

// Removes the materials no object uses and the images no material uses, renumbering the rest
// in their order.
void dropUnusedMaterials(Model& model);

// Checks the invariants above (sizes, offsets, index ranges); for tests and debug builds.
bool isConsistent(const Model& model, std::string* why = nullptr);

}  // namespace lodforge
