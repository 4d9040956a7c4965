#include "lodforge/tiles/tile_features.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <string>

#include <nlohmann/json.hpp>

namespace lodforge {
namespace {

constexpr int kUnsignedShort = 5123, kFloat = 5126;

// A STRING property's two views (EXT_structural_metadata): the UTF-8 bytes back to back and
// UINT32 offsets, one per row plus the end.
Result<nlohmann::json> addStrings(GlbWriter& writer, std::span<const std::uint32_t> parts,
                                  const std::vector<std::string>& strings) {
  std::string values;
  std::vector<std::uint32_t> offsets{0};
  for (std::uint32_t part : parts) {
    values += strings[part];
    offsets.push_back(static_cast<std::uint32_t>(values.size()));
  }
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
            {"source",
             {{"type", "STRING"}, {"description", "The file the part was read from."}}}}}}}}}};
  const nlohmann::json metadata = {{"schema", schema},
                                   {"propertyTables",
                                    {{{"class", "part"},
                                      {"count", parts.size()},
                                      {"properties",
                                       {{"id", {{"values", *idView}}},
                                        {"name", *names},
                                        {"path", *paths},
                                        {"source", *source}}}}}}};
  writer.setStructuralMetadata(metadata.dump());
  return {};
}

}  // namespace lodforge
