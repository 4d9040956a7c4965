// The lidar attributes of a point tile, the 3D Tiles 1.1 way: a glTF vertex attribute per field
// ("_CLASSIFICATION", "_INTENSITY", …) and the EXT_structural_metadata that describes them — a
// schema with one class (`lidar`; classification an enum of the ASPRS class names) and a property
// attribute that maps each property to its vertex attribute — so CesiumJS styles and three.js
// shaders can use them by name.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lodforge/core/status.h"
#include "lodforge/io/mesh/glb_writer.h"
#include "lodforge/io/points/point_extras.h"
#include "lodforge/points/partition.h"

namespace lodforge {

// One lidar field as tiles carry it (and info names it): its bit, property name, vertex
// attribute, glTF and metadata component types, and its value from a point.
struct PointAttributeField {
  std::uint32_t bit;
  const char* property;      // "classification", "return_number", …
  const char* semantic;      // "_CLASSIFICATION", …
  int componentType;         // glTF's, of the vertex attribute
  const char* metadataType;  // componentType of the class property, or "ENUM"
  double (*value)(const PointAttributes&);
};
std::span<const PointAttributeField> pointAttributeFields();

struct PointTileAttributes {
  std::vector<std::vector<std::byte>> data;  // 4 bytes per point each
  std::vector<GlbVertexAttribute> attributes;
  std::string metadata;  // the EXT_structural_metadata object; empty without attributes
};

// The extra fields of the same points: their layout and `stride` bytes a point.
struct PointTileExtras {
  const PointExtras* layout = nullptr;
  std::span<const std::byte> bytes;
};

// The fields `mask` (PointAttributeBit) names, of `points`; with kAttrExtras, also every extra
// field (8- and 16-bit integers as they are, the others as FLOAT32 of their scaled value, from
// the tile's least whole value where the type is wider than a float holds exactly).
PointTileAttributes pointTileAttributes(std::span<const CloudPoint> points, std::uint32_t mask,
                                        PointTileExtras extras = {});

// The property names extra fields take in tiles: the field's name with each character other
// than a letter, digit or '_' made '_' (and '_' before a leading digit), unique among the lidar
// properties and each other regardless of case (their attribute is "_" + the name upper-cased).
std::vector<std::string> extraPropertyNames(const PointExtras& extras);

// The names `--attributes` takes, as PointAttributeBits ("all" and "none" too); bad input names
// the unknown one.
Result<std::uint32_t> parsePointAttributes(const std::string& list);
std::string pointAttributeNames(std::uint32_t mask);  // "classification, intensity, …"

// "Ground", "Low Vegetation", … (LAS 1.4 R15, Table 17); "Class N" for the others.
std::string asprsClassName(std::uint8_t classification);

}  // namespace lodforge
