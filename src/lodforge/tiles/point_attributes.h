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
#include "lodforge/io/glb_writer.h"
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

// The fields `mask` (PointAttributeBit) names, of `points`.
PointTileAttributes pointTileAttributes(std::span<const CloudPoint> points, std::uint32_t mask);

// The names `--attributes` takes, as PointAttributeBits ("all" and "none" too); bad input names
// the unknown one.
Result<std::uint32_t> parsePointAttributes(const std::string& list);
std::string pointAttributeNames(std::uint32_t mask);  // "classification, intensity, …"

// "Ground", "Low Vegetation", … (LAS 1.4 R15, Table 17); "Class N" for the others.
std::string asprsClassName(std::uint8_t classification);

}  // namespace lodforge
