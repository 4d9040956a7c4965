#include "lodforge/tiles/point_attributes.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <set>

#include <nlohmann/json.hpp>

#include "lodforge/io/mesh/gltf_constants.h"

namespace lodforge {

namespace {

using namespace gltf;  // the component types

using Field = PointAttributeField;

bool isAsciiAlnum(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

// Property names are ASCII identifiers: their attribute (and clash test) is "_" + upper case.
std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

// The names `--attributes` takes: one per bit (returns covers both return fields).
struct Named {
  const char* name;
  std::uint32_t bit;
};
constexpr std::array<Named, 10> kNames = {{{"classification", kAttrClassification},
                                           {"intensity", kAttrIntensity},
                                           {"returns", kAttrReturns},
                                           {"flags", kAttrFlags},
                                           {"scan-angle", kAttrScanAngle},
                                           {"user-data", kAttrUserData},
                                           {"point-source", kAttrPointSource},
                                           {"gps-time", kAttrGpsTime},
                                           {"nir", kAttrNir},
                                           {"extras", kAttrExtras}}};

// Each value in 4 bytes (glTF aligns vertex attribute elements to 4); GPS time as a float from
// the tile's first whole second, which the property attribute's offset adds back.
std::vector<std::byte> packField(const Field& field, std::span<const CloudPoint> points,
                                 double offset) {
  std::vector<std::byte> bytes(4 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double v = field.value(points[i].attributes);
    std::byte* at = bytes.data() + 4 * i;
    if (field.componentType == kFloat) {
      const auto f = static_cast<float>(v - offset);
      std::memcpy(at, &f, 4);
    } else if (field.componentType == kUnsignedShort) {
      const auto u = static_cast<std::uint16_t>(v);
      std::memcpy(at, &u, 2);
    } else {
      at[0] = static_cast<std::byte>(static_cast<std::uint8_t>(v));
    }
  }
  return bytes;
}

// How an extra field goes into a tile: 8- and 16-bit integers as they are stored (their glTF
// component type), the rest as FLOAT32 of value − offset. `noData` is what the tile stores for
// "none": the field's own no-data value, or for floats without one that are NaN or infinite
// somewhere (which glTF accessors may not hold) the lowest float.
struct ExtraColumn {
  int componentType = kFloat;
  const char* metadataType = "FLOAT32";
  double offset = 0;  // the tile's least whole value, where a float would lose digits
  std::optional<double> noData;
};

bool isNoData(const std::byte* point, const ExtraField& field) {
  return field.noData && extraRaw(point, field) == *field.noData;
}

ExtraColumn extraColumn(const ExtraField& field, const PointTileExtras& extras, std::size_t count) {
  const std::uint32_t stride = extras.layout->stride;
  if (!field.scaled()) {
    const std::optional<double> raw = field.noData;
    switch (field.type) {
      case ExtraType::kInt8:
        return {kByte, "INT8", 0, raw};
      case ExtraType::kUint8:
        return {kUnsignedByte, "UINT8", 0, raw};
      case ExtraType::kInt16:
        return {kShort, "INT16", 0, raw};
      case ExtraType::kUint16:
        return {kUnsignedShort, "UINT16", 0, raw};
      default:
        break;
    }
  }
  double least = std::numeric_limits<double>::infinity();
  bool nonFinite = false;
  for (std::size_t i = 0; i < count; ++i) {
    const std::byte* point = extras.bytes.data() + i * stride;
    if (isNoData(point, field)) continue;
    const double v = extraValue(point, field);
    if (!std::isfinite(v)) {
      nonFinite = true;
    } else {
      least = std::min(least, v);
    }
  }
  ExtraColumn column;
  // A float32 holds its own values exactly; wider types lose digits far from zero.
  const bool exact = field.type == ExtraType::kFloat32 && !field.scaled();
  column.offset = exact || !std::isfinite(least) ? 0.0 : std::floor(least);
  if (field.noData) {
    column.noData = static_cast<float>(*field.noData * field.scale + field.add - column.offset);
  } else if (nonFinite) {
    column.noData = std::numeric_limits<float>::lowest();
  }
  return column;
}

std::vector<std::byte> packExtra(const ExtraField& field, const ExtraColumn& column,
                                 const PointTileExtras& extras, std::size_t count) {
  const std::uint32_t stride = extras.layout->stride;
  std::vector<std::byte> bytes(4 * count);
  const std::size_t size = extraTypeSize(field.type);
  for (std::size_t i = 0; i < count; ++i) {
    const std::byte* point = extras.bytes.data() + i * stride;
    if (column.componentType != kFloat) {
      std::memcpy(bytes.data() + 4 * i, point + field.offset, size);
      continue;
    }
    const double v = extraValue(point, field);
    const auto f = isNoData(point, field) || !std::isfinite(v)
                       ? static_cast<float>(*column.noData)
                       : static_cast<float>(v - column.offset);
    std::memcpy(bytes.data() + 4 * i, &f, 4);
  }
  return bytes;
}

// The class property of an extra field, with its description and what means "none".
nlohmann::json extraProperty(const ExtraField& field, const ExtraColumn& column) {
  nlohmann::json property = {{"type", "SCALAR"}, {"componentType", column.metadataType}};
  if (!field.description.empty()) property["description"] = field.description;
  if (column.noData) {
    if (column.componentType == kFloat) {
      property["noData"] = static_cast<float>(*column.noData);
    } else {
      property["noData"] = static_cast<std::int64_t>(*column.noData);
    }
  }
  return property;
}

nlohmann::json classificationEnum(std::span<const CloudPoint> points) {
  std::array<bool, 256> used{};  // a table, not a set: this runs over every point of every tile
  for (int c = 0; c <= 22; ++c) used[static_cast<std::size_t>(c)] = true;
  for (const CloudPoint& p : points) used[p.attributes.classification] = true;
  nlohmann::json list = nlohmann::json::array();
  for (int c = 0; c < 256; ++c)
    if (used[static_cast<std::size_t>(c)])
      list.push_back({{"name", asprsClassName(static_cast<std::uint8_t>(c))}, {"value", c}});
  return {{"valueType", "UINT8"}, {"values", list}};
}

}  // namespace

std::span<const PointAttributeField> pointAttributeFields() {
  using A = PointAttributes;
  static const std::array<PointAttributeField, 10> kFields = {{
      {kAttrClassification, "classification", "_CLASSIFICATION", kUnsignedByte, "ENUM",
       [](const A& a) -> double { return a.classification; }},
      {kAttrIntensity, "intensity", "_INTENSITY", kUnsignedShort, "UINT16",
       [](const A& a) -> double { return a.intensity; }},
      {kAttrReturns, "return_number", "_RETURN_NUMBER", kUnsignedByte, "UINT8",
       [](const A& a) -> double { return a.returnNumber; }},
      {kAttrReturns, "number_of_returns", "_NUMBER_OF_RETURNS", kUnsignedByte, "UINT8",
       [](const A& a) -> double { return a.numberOfReturns; }},
      {kAttrFlags, "classification_flags", "_CLASSIFICATION_FLAGS", kUnsignedByte, "UINT8",
       [](const A& a) -> double { return a.flags & 15; }},
      {kAttrScanAngle, "scan_angle", "_SCAN_ANGLE", kFloat, "FLOAT32",
       [](const A& a) -> double { return a.scanAngle; }},
      {kAttrUserData, "user_data", "_USER_DATA", kUnsignedByte, "UINT8",
       [](const A& a) -> double { return a.userData; }},
      {kAttrPointSource, "point_source_id", "_POINT_SOURCE_ID", kUnsignedShort, "UINT16",
       [](const A& a) -> double { return a.pointSource; }},
      {kAttrGpsTime, "gps_time", "_GPS_TIME", kFloat, "FLOAT32",
       [](const A& a) -> double { return a.gpsTime; }},
      {kAttrNir, "nir", "_NIR", kUnsignedShort, "UINT16",
       [](const A& a) -> double { return a.nir; }},
  }};
  return kFields;
}

std::string asprsClassName(std::uint8_t classification) {
  static constexpr std::array<const char*, 23> kNames = {"Created, never classified",
                                                         "Unclassified",
                                                         "Ground",
                                                         "Low Vegetation",
                                                         "Medium Vegetation",
                                                         "High Vegetation",
                                                         "Building",
                                                         "Low Point (noise)",
                                                         "Reserved",
                                                         "Water",
                                                         "Rail",
                                                         "Road Surface",
                                                         "Reserved (overlap)",
                                                         "Wire - Guard (Shield)",
                                                         "Wire - Conductor (Phase)",
                                                         "Transmission Tower",
                                                         "Wire-Structure Connector (Insulator)",
                                                         "Bridge Deck",
                                                         "High Noise",
                                                         "Overhead Structure",
                                                         "Ignored Ground",
                                                         "Snow",
                                                         "Temporal Exclusion"};
  if (classification < kNames.size()) return kNames[classification];
  return fmt::format("Class {}", classification);
}

PointTileAttributes pointTileAttributes(std::span<const CloudPoint> points, std::uint32_t mask,
                                        PointTileExtras extras) {
  PointTileAttributes out;
  if (mask == 0 || points.empty()) return out;
  double firstSecond = points.front().attributes.gpsTime;
  for (const CloudPoint& p : points) firstSecond = std::min(firstSecond, p.attributes.gpsTime);
  firstSecond = std::floor(firstSecond);
  nlohmann::json properties = nlohmann::json::object(), mapped = nlohmann::json::object();
  for (const Field& field : pointAttributeFields()) {
    if ((mask & field.bit) == 0) continue;
    const bool time = field.bit == kAttrGpsTime;
    out.data.push_back(packField(field, points, time ? firstSecond : 0));
    out.attributes.push_back({field.semantic, field.componentType, {}});
    properties[field.property] =
        field.bit == kAttrClassification
            ? nlohmann::json{{"type", "ENUM"}, {"enumType", "classification"}}
            : nlohmann::json{{"type", "SCALAR"}, {"componentType", field.metadataType}};
    mapped[field.property] = {{"attribute", field.semantic}};
    if (time) mapped[field.property]["offset"] = firstSecond;
  }
  if ((mask & kAttrExtras) != 0 && extras.layout != nullptr) {
    assert(extras.bytes.size() == points.size() * extras.layout->stride);
    const std::vector<std::string> names = extraPropertyNames(*extras.layout);
    for (std::size_t f = 0; f < names.size(); ++f) {
      const ExtraField& field = extras.layout->fields[f];
      const ExtraColumn column = extraColumn(field, extras, points.size());
      const std::string semantic = "_" + upper(names[f]);
      out.data.push_back(packExtra(field, column, extras, points.size()));
      out.attributes.push_back({semantic, column.componentType, {}});
      properties[names[f]] = extraProperty(field, column);
      mapped[names[f]] = {{"attribute", semantic}};
      if (column.offset != 0) mapped[names[f]]["offset"] = column.offset;
    }
  }
  if (out.attributes.empty()) return out;
  // Spans into `data`, complete now.
  for (std::size_t i = 0; i < out.attributes.size(); ++i) out.attributes[i].data = out.data[i];
  nlohmann::json schema = {
      {"id", "lodforge_lidar"},
      {"classes", {{"lidar", {{"name", "Lidar point"}, {"properties", properties}}}}}};
  if ((mask & kAttrClassification) != 0)
    schema["enums"]["classification"] = classificationEnum(points);
  const nlohmann::json metadata = {
      {"schema", schema}, {"propertyAttributes", {{{"class", "lidar"}, {"properties", mapped}}}}};
  out.metadata = metadata.dump();
  return out;
}

std::vector<std::string> extraPropertyNames(const PointExtras& extras) {
  std::set<std::string> taken;  // upper case
  for (const Field& field : pointAttributeFields()) taken.insert(upper(field.property));
  std::vector<std::string> names;
  for (const ExtraField& field : extras.fields) {
    std::string name = field.name.empty() ? "extra" : field.name;
    for (char& c : name)
      if (!isAsciiAlnum(c) && c != '_') c = '_';
    if (name.front() >= '0' && name.front() <= '9') name = "_" + name;
    std::string unique = name;
    for (int n = 2; taken.count(upper(unique)) != 0; ++n) unique = fmt::format("{}_{}", name, n);
    taken.insert(upper(unique));
    names.push_back(std::move(unique));
  }
  return names;
}

Result<std::uint32_t> parsePointAttributes(const std::string& list) {
  if (list == "all") return ~std::uint32_t{0};
  if (list == "none" || list.empty()) return std::uint32_t{0};
  std::uint32_t mask = 0;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string name = list.substr(start, comma - start);
    const auto known =
        std::find_if(kNames.begin(), kNames.end(), [&](const Named& n) { return name == n.name; });
    if (known == kNames.end())
      return Error{ErrorKind::kUsage,
                   fmt::format("--attributes: \"{}\" is not one of all, none, {}", name,
                               pointAttributeNames(~std::uint32_t{0}))};
    mask |= known->bit;
    start = comma + 1;
  }
  return mask;
}

std::string pointAttributeNames(std::uint32_t mask) {
  std::string names;
  for (const Named& n : kNames) {
    if ((mask & n.bit) == 0) continue;
    if (!names.empty()) names += ", ";
    names += n.name;
  }
  return names;
}

}  // namespace lodforge
