#include "info_attributes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "lodforge/core/progress.h"
#include "lodforge/core/units.h"
#include "lodforge/io/points/point_reader.h"
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

// Classification is counted per class, not ranged; scan angles are shown to the millidegree.
bool ranged(const PointAttributeField& field) {
  return field.bit != kAttrClassification;
}
double shown(const PointAttributeField& field, const PointAttributes& a) {
  const double v = field.value(a);
  return field.bit == kAttrScanAngle ? std::round(v * 1000.0) / 1000.0 : v;
}

}  // namespace

ExtraRanges::ExtraRanges(const PointExtras& extras)
    : extras_(extras),
      min_(extras.fields.size(), std::numeric_limits<double>::infinity()),
      max_(extras.fields.size(), -std::numeric_limits<double>::infinity()),
      noData_(extras.fields.size(), 0) {}

void ExtraRanges::add(std::span<const std::byte> points) {
  if (extras_.stride == 0) return;
  for (std::size_t at = 0; at + extras_.stride <= points.size(); at += extras_.stride) {
    for (std::size_t f = 0; f < extras_.fields.size(); ++f) {
      const ExtraField& field = extras_.fields[f];
      if (field.noData && extraRaw(points.data() + at, field) == *field.noData) {
        ++noData_[f];
        continue;
      }
      const double v = extraValue(points.data() + at, field);
      min_[f] = std::min(min_[f], v);
      max_[f] = std::max(max_[f], v);
    }
  }
}

nlohmann::json ExtraRanges::json() const {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t f = 0; f < extras_.fields.size(); ++f) {
    const ExtraField& field = extras_.fields[f];
    nlohmann::json entry = {{"name", field.name}, {"type", extraTypeName(field.type)}};
    if (!field.description.empty()) entry["description"] = field.description;
    if (field.scaled()) {
      entry["scale"] = field.scale;
      entry["offset"] = field.add;
    }
    if (min_[f] <= max_[f]) {
      entry["min"] = min_[f];
      entry["max"] = max_[f];
    }
    if (field.noData) {
      entry["noData"] = *field.noData;
      entry["noDataPoints"] = noData_[f];
    }
    list.push_back(std::move(entry));
  }
  return list;
}

Result<nlohmann::json> scanPointAttributes(const std::string& path, std::uint64_t fileBytes) {
  Result<PointReader> reader = PointReader::open(path);
  if (!reader) return reader.status();
  const std::uint32_t mask = reader->info().attributes;
  const auto fields = pointAttributeFields();
  std::vector<Range> ranges(fields.size());
  std::array<std::uint64_t, 256> classes{};
  ExtraRanges extras(reader->info().extras);
  Progress progress("reading", reader->info().count.value_or(fileBytes / 20));
  PointBatch batch;
  while (true) {
    LODFORGE_TRY(checkCancelled());
    Result<bool> more = reader->next(batch);
    if (!more) return more.status();
    if (!*more) break;
    for (const PointAttributes& a : batch.attributes) {
      for (std::size_t f = 0; f < fields.size(); ++f)
        if ((mask & fields[f].bit) != 0 && ranged(fields[f])) ranges[f].add(shown(fields[f], a));
      ++classes[a.classification];
    }
    extras.add(batch.extras);
    progress.advance(batch.size());
  }
  progress.finish();
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t f = 0; f < fields.size(); ++f)
    if (ranges[f].min <= ranges[f].max)
      j[fields[f].property] = {{"min", ranges[f].min}, {"max", ranges[f].max}};
  if (nlohmann::json list = extras.json(); !list.empty()) j["extras"] = std::move(list);
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
  for (const PointAttributeField& field : pointAttributeFields()) {
    if (!attributes.contains(field.property) || !ranged(field)) continue;
    const nlohmann::json& range = attributes[field.property];
    fmt::print("{:<22}{:.10g} to {:.10g}\n", field.property, range["min"].get<double>(),
               range["max"].get<double>());
  }
  if (attributes.contains("extras")) {
    for (const nlohmann::json& e : attributes["extras"]) {
      std::string range = "no values";
      if (e.contains("min"))
        range = fmt::format("{:.10g} to {:.10g}", e["min"].get<double>(), e["max"].get<double>());
      std::string notes = e["type"].get<std::string>();
      if (e.contains("scale"))
        notes += fmt::format(", ×{:g} + {:g}", e["scale"].get<double>(), e["offset"].get<double>());
      if (e.contains("noData"))
        notes += fmt::format(", no data {:g} at {} points", e["noData"].get<double>(),
                             formatCount(e["noDataPoints"].get<std::uint64_t>()));
      if (e.contains("description")) notes += ", " + e["description"].get<std::string>();
      fmt::print("{:<22}{} (extra: {})\n", e["name"].get<std::string>(), range, notes);
    }
  }
  if (!attributes.contains("classification")) return;
  // JSON keys are text ("11" < "2"): the classes are listed by their number.
  std::vector<std::pair<int, const nlohmann::json*>> classes;
  for (const auto& [value, entry] : attributes["classification"].items())
    classes.emplace_back(std::stoi(value), &entry);
  std::sort(classes.begin(), classes.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [value, entry] : classes)
    fmt::print("class {:<9}{} points, {}\n", value,
               formatCount((*entry)["points"].get<std::uint64_t>()),
               (*entry)["name"].get<std::string>());
}

}  // namespace lodforge::cli
