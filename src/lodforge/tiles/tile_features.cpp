#include "lodforge/tiles/tile_features.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <string>

#include <nlohmann/json.hpp>

#include "lodforge/io/mesh/gltf_constants.h"

namespace lodforge {
namespace {

using namespace gltf;  // the component types

// A STRING property's two views (EXT_structural_metadata): the UTF-8 bytes back to back and
// UINT32 offsets, one per row plus the end. Null when every string is empty (a buffer view may
// not be empty; the property is left out of the table, as the class allows).
Result<nlohmann::json> addStrings(GlbWriter& writer, std::span<const std::uint32_t> parts,
                                  const std::vector<std::string>& strings) {
  std::string values;
  std::vector<std::uint32_t> offsets{0};
  for (std::uint32_t part : parts) {
    values += strings[part];
    offsets.push_back(static_cast<std::uint32_t>(values.size()));
  }
  if (values.empty()) return nlohmann::json();
  Result<std::uint32_t> valueView = writer.addBufferView(std::as_bytes(std::span(values)));
  if (!valueView) return valueView.status();
  Result<std::uint32_t> offsetView = writer.addBufferView(std::as_bytes(std::span(offsets)));
  if (!offsetView) return offsetView.status();
  return nlohmann::json{
      {"values", *valueView}, {"stringOffsets", *offsetView}, {"stringOffsetType", "UINT32"}};
}

}  // namespace

TileFeatures tileFeatures(std::span<const std::uint32_t> features) {
  TileFeatures out;
  out.parts.assign(features.begin(), features.end());
  std::sort(out.parts.begin(), out.parts.end());
  out.parts.erase(std::unique(out.parts.begin(), out.parts.end()), out.parts.end());
  out.rows.resize(features.size());
  for (std::size_t v = 0; v < features.size(); ++v) {
    const auto at = std::lower_bound(out.parts.begin(), out.parts.end(), features[v]);
    out.rows[v] = static_cast<std::uint32_t>(at - out.parts.begin());
  }
  return out;
}

GlbVertexAttribute featureIdAttribute(std::span<const std::uint32_t> rows,
                                      std::vector<std::byte>& storage) {
  const bool narrow =
      std::all_of(rows.begin(), rows.end(), [](std::uint32_t r) { return r < 65536; });
  storage.assign(4 * rows.size(), std::byte{0});
  for (std::size_t v = 0; v < rows.size(); ++v) {
    if (narrow) {
      const auto row = static_cast<std::uint16_t>(rows[v]);
      std::memcpy(storage.data() + 4 * v, &row, sizeof row);
    } else {
      const auto row = static_cast<float>(rows[v]);
      std::memcpy(storage.data() + 4 * v, &row, sizeof row);
    }
  }
  return {"_FEATURE_ID_0", narrow ? kUnsignedShort : kFloat, storage};
}

std::vector<TriangleGroup> groupTriangles(std::span<std::uint32_t> indices,
                                          std::span<const std::uint32_t> keyOf) {
  const std::size_t triangles = indices.size() / 3;
  assert(keyOf.size() == triangles);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> order(triangles);  // key, triangle
  for (std::size_t t = 0; t < triangles; ++t) order[t] = {keyOf[t], static_cast<std::uint32_t>(t)};
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  const std::vector<std::uint32_t> before(indices.begin(), indices.end());
  std::vector<TriangleGroup> groups;
  for (std::size_t i = 0; i < triangles; ++i) {
    const auto [key, t] = order[i];
    for (std::size_t k = 0; k < 3; ++k) indices[3 * i + k] = before[3 * std::size_t{t} + k];
    if (groups.empty() || key != groups.back().key) groups.push_back({key, 0});
    groups.back().indexCount += 3;
  }
  return groups;
}

std::vector<GlbPrimitive> groupByMaterial(GlbWriter& writer, const PartTable& table,
                                          std::span<const std::uint32_t> vertexFeatures,
                                          std::span<std::uint32_t> indices, bool vertexColors) {
  std::vector<std::uint32_t> materialOf(indices.size() / 3);
  for (std::size_t t = 0; t < materialOf.size(); ++t) {
    const std::uint32_t part = vertexFeatures[indices[3 * t]];
    materialOf[t] = part < table.materials.size() ? table.materials[part] : kNoMaterial;
  }
  std::vector<GlbPrimitive> primitives;
  for (const TriangleGroup& group : groupTriangles(indices, materialOf)) {
    std::optional<std::uint32_t> written;
    if (group.key < table.materialTable.size()) {
      Material m = table.materialTable[group.key];
      if (vertexColors) m.baseColor = {1, 1, 1, 1};
      written = writer.addMaterial(m);
    }
    primitives.push_back({group.indexCount, written});
  }
  return primitives;
}

Status addPartTable(GlbWriter& writer, const PartTable& table,
                    std::span<const std::uint32_t> parts) {
  assert(table.paths.size() == table.names.size());
  const std::vector<std::uint32_t> ids(parts.begin(), parts.end());
  Result<std::uint32_t> idView = writer.addBufferView(std::as_bytes(std::span(ids)));
  if (!idView) return idView.status();
  Result<nlohmann::json> names = addStrings(writer, parts, table.names);
  if (!names) return names.status();
  Result<nlohmann::json> paths = addStrings(writer, parts, table.paths);
  if (!paths) return paths.status();
  // Each row's material and layer by name (empty: none), for the tile's own parts only.
  std::vector<std::string> materialNames(parts.size()), layerNames(parts.size());
  std::vector<std::uint32_t> rows(parts.size());
  for (std::size_t r = 0; r < parts.size(); ++r) {
    rows[r] = static_cast<std::uint32_t>(r);
    const std::uint32_t m =
        parts[r] < table.materials.size() ? table.materials[parts[r]] : kNoMaterial;
    if (m < table.materialTable.size()) materialNames[r] = table.materialTable[m].name;
    const std::uint32_t l = parts[r] < table.layers.size() ? table.layers[parts[r]] : kNoLayer;
    if (l < table.layerTable.size()) layerNames[r] = table.layerTable[l];
  }
  Result<nlohmann::json> material = addStrings(writer, rows, materialNames);
  if (!material) return material.status();
  Result<nlohmann::json> layer = addStrings(writer, rows, layerNames);
  if (!layer) return layer.status();
  const std::vector<std::string> sources(1, table.source);
  const std::vector<std::uint32_t> zeros(parts.size(), 0);
  Result<nlohmann::json> source = addStrings(writer, zeros, sources);
  if (!source) return source.status();
  const nlohmann::json schema = {
      {"id", "lodforge_parts"},
      {"classes",
       {{"part",
         {{"name", "Part"},
          {"description", "An object of the input: a CAD part placed in its assembly."},
          {"properties",
           {{"id",
             {{"type", "SCALAR"},
              {"componentType", "UINT32"},
              {"description", "The part's number in the whole tileset (parts.json)."}}},
            {"name", {{"type", "STRING"}, {"semantic", "NAME"}}},
            {"path",
             {{"type", "STRING"},
              {"description", "Names from the assembly's root down to the part, /-separated."}}},
            {"material", {{"type", "STRING"}, {"description", "The name of the part's material."}}},
            {"layer",
             {{"type", "STRING"},
              {"description", "The part's CAD layers, \"; \"-separated (empty: none)."}}},
            {"source",
             {{"type", "STRING"}, {"description", "The file the part was read from."}}}}}}}}}};
  nlohmann::json metadata = {{"schema", schema},
                             {"propertyTables",
                              {{{"class", "part"},
                                {"count", parts.size()},
                                {"properties", {{"id", {{"values", *idView}}}}}}}}};
  // A column left out goes from the class too: 3d-tiles-renderer 0.4 reads every class property
  // from the table.
  auto& properties = metadata["propertyTables"][0]["properties"];
  auto& declared = metadata["schema"]["classes"]["part"]["properties"];
  const std::pair<const char*, const nlohmann::json*> strings[] = {{"name", &*names},
                                                                   {"path", &*paths},
                                                                   {"material", &*material},
                                                                   {"layer", &*layer},
                                                                   {"source", &*source}};
  for (const auto& [key, value] : strings) {
    if (value->is_null()) {
      declared.erase(key);
    } else {
      properties[key] = *value;
    }
  }
  writer.setStructuralMetadata(metadata.dump());
  return {};
}

}  // namespace lodforge
