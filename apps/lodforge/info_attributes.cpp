#include "info_attributes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>

#include <fmt/format.h>

#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/io/point_reader.h"
#include "lodforge/tiles/point_attributes.h"

namespace lodforge::cli {

namespace {

struct Range {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  void add(double v) {
    min = std::min(min, v);
    max = std::max(max, v);
  }
};

struct RangedField {
  std::uint32_t bit;
  const char* name;
  std::function<double(const PointAttributes&)> value;
};

const std::vector<RangedField>& rangedFields() {
  static const std::vector<RangedField> kFields = {
      {kAttrIntensity, "intensity", [](const PointAttributes& a) { return a.intensity; }},
      {kAttrReturns, "returnNumber", [](const PointAttributes& a) { return a.returnNumber; }},
      {kAttrReturns, "numberOfReturns",
       [](const PointAttributes& a) { return a.numberOfReturns; }},
      {kAttrFlags, "classificationFlags", [](const PointAttributes& a) { return a.flags & 15; }},
      {kAttrScanAngle, "scanAngle",
       [](const PointAttributes& a) { return std::round(a.scanAngle * 1000.0) / 1000.0; }},
      {kAttrUserData, "userData", [](const PointAttributes& a) { return a.userData; }},
      {kAttrPointSource, "pointSource", [](const PointAttributes& a) { return a.pointSource; }},
      {kAttrGpsTime, "gpsTime", [](const PointAttributes& a) { return a.gpsTime; }},
      {kAttrNir, "nir", [](const PointAttributes& a) { return a.nir; }},
  };
  return kFields;
}

}  // namespace

Result<nlohmann::json> scanPointAttributes(const std::string& path, std::uint64_t fileBytes) {
  Result<PointReader> reader = PointReader::open(path);
  if (!reader) return reader.status();
  const std::uint32_t mask = reader->info().attributes;
  std::vector<Range> ranges(rangedFields().size());
  std::array<std::uint64_t, 256> classes{};
  Progress progress("reading", reader->info().count.value_or(fileBytes / 20));
  PointBatch batch;
  while (true) {
    LODFORGE_TRY(checkCancelled());
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) break;
    for (const PointAttributes& a : batch.attributes) {
      for (std::size_t f = 0; f < ranges.size(); ++f)
        if ((mask & rangedFields()[f].bit) != 0) ranges[f].add(rangedFields()[f].value(a));
      ++classes[a.classification];
    }
    progress.advance(batch.size());
  }
  progress.finish();
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t f = 0; f < ranges.size(); ++f)
    if ((mask & rangedFields()[f].bit) != 0 && ranges[f].min <= ranges[f].max)
      j[rangedFields()[f].name] = {{"min", ranges[f].min}, {"max", ranges[f].max}};
  if ((mask & kAttrClassification) != 0) {
    nlohmann::json counts = nlohmann::json::object();
    for (std::size_t c = 0; c < classes.size(); ++c)
      if (classes[c] != 0)
        counts[std::to_string(c)] = {{"name", asprsClassName(static_cast<std::uint8_t>(c))},
                                     {"points", classes[c]}};
    j["classification"] = counts;
  }
  return j;
}

void printPointAttributes(const nlohmann::json& attributes) {
  static const std::vector<std::pair<const char*, const char*>> kLabels = {
      {"intensity", "intensity"},     {"returnNumber", "return number"},
      {"numberOfReturns", "returns"}, {"classificationFlags", "class flags"},
      {"scanAngle", "scan angle °"},  {"userData", "user data"},
      {"pointSource", "point source"}, {"gpsTime", "GPS time"},
      {"nir", "NIR"}};
  for (const auto& [key, label] : kLabels) {
    if (!attributes.contains(key)) continue;
    fmt::print("{:<15}{:.10g} to {:.10g}\n", label, attributes[key]["min"].get<double>(),
               attributes[key]["max"].get<double>());
  }
  if (!attributes.contains("classification")) return;
  for (const auto& [value, entry] : attributes["classification"].items())
    fmt::print("class {:<9}{} points, {}\n", value,
               formatCount(entry["points"].get<std::uint64_t>()),
               entry["name"].get<std::string>());
}

}  // namespace lodforge::cli
