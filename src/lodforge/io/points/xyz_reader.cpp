#include "lodforge/io/points/xyz_reader.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <vector>

namespace lodforge {

namespace {

bool isComment(std::string_view line) {
  const std::size_t start = line.find_first_not_of(" \t");
  if (start == std::string_view::npos) return true;  // blank
  line.remove_prefix(start);
  return line.starts_with('#') || line.starts_with("//");
}

char detectSeparator(std::string_view line) {
  if (line.find(',') != std::string_view::npos) return ',';
  if (line.find(';') != std::string_view::npos) return ';';
  return ' ';
}

std::string_view trim(std::string_view s) {
  const std::size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string_view::npos) return {};
  const std::size_t b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

void split(std::string_view line, char separator, std::vector<std::string_view>& fields) {
  fields.clear();
  if (separator == ' ') {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
      if (i == line.size()) break;
      const std::size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
      fields.push_back(line.substr(start, i - start));
    }
    return;
  }
  std::size_t start = 0;
  while (true) {
    const std::size_t end = line.find(separator, start);
    fields.push_back(trim(line.substr(start, end - start)));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
}

std::optional<double> number(std::string_view field) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  double value = 0;
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (error != std::errc() || end != field.data() + field.size()) return std::nullopt;
  return value;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

struct XyzReader::State {
  std::optional<ByteSource> source;
  XyzLayout layout;
  std::size_t batchSize = 1 << 16;
  std::uint64_t line = 0;  // of the last line read
  std::uint64_t nextPoint = 0;
  std::string text;
  bool pending = false;  // `text` holds the first data line, not yet delivered
  std::vector<std::string_view> fields;

  Error fail(std::string_view what) const { return badInputAtLine(source->name(), line, what); }
  // The next line that is neither blank nor a comment; false at the end.
  bool nextLine() {
    while (source->readLine(text)) {
      ++line;
      if (!isComment(text)) return true;
    }
    return false;
  }

  // The steps of start(), over the first line of numbers (`text`, split into `fields`).
  Result<bool> findFirstPoint(std::vector<std::string>& names);
  Status columnsFromNames(const std::vector<std::string>& names);
  Status columnsFromCount();
  bool colorsInUnits() const;
  double value(int column) const { return *number(fields[static_cast<std::size_t>(column)]); }
};

XyzReader::XyzReader(std::unique_ptr<State> state) : state_(std::move(state)) {}
XyzReader::XyzReader(XyzReader&&) noexcept = default;
XyzReader& XyzReader::operator=(XyzReader&&) noexcept = default;
XyzReader::~XyzReader() = default;

const XyzLayout& XyzReader::layout() const {
  return state_->layout;
}

Result<XyzReader> XyzReader::open(const std::string& path, std::size_t batchSize) {
  Result<ByteSource> source = ByteSource::openFile(path);
  if (!source) return source.status();
  auto state = std::make_unique<State>();
  state->source.emplace(std::move(*source));
  state->batchSize = std::max<std::size_t>(1, batchSize);
  return start(std::move(state));
}

Result<XyzReader> XyzReader::fromMemory(std::span<const std::byte> bytes, std::string name,
                                        std::size_t batchSize) {
  auto state = std::make_unique<State>();
  state->source.emplace(ByteSource::fromMemory(bytes, std::move(name)));
  state->batchSize = std::max<std::size_t>(1, batchSize);
  return start(std::move(state));
}

// Reads up to the first line of numbers (false: the file has none), past comments, a PTS count
// line and a line of column names, whose names go to `names` (lower case). CloudCompare writes
// its column names as a comment: "//X,Y,Z,R,G,B".
Result<bool> XyzReader::State::findFirstPoint(std::vector<std::string>& names) {
  while (true) {
    if (!source->readLine(text)) return false;
    ++line;
    const std::string_view trimmed = trim(text);
    if (trimmed.starts_with("//") && names.empty()) {
      split(trimmed.substr(2), detectSeparator(trimmed), fields);
      if (!fields.empty() && lower(fields[0]) == "x") {
        for (std::string_view f : fields) names.push_back(lower(f));
      }
      continue;
    }
    if (isComment(trimmed)) continue;
    layout.separator = detectSeparator(text);
    split(text, layout.separator, fields);
    const bool numeric = std::all_of(fields.begin(), fields.end(),
                                     [](std::string_view f) { return number(f).has_value(); });
    if (numeric && fields.size() == 1 && names.empty()) continue;  // a PTS count line
    if (numeric) return true;
    if (!names.empty()) return fail("expected numbers after the line of column names");
    for (std::string_view f : fields) names.push_back(lower(f));
  }
}

// The columns by their names: x, y and z must be there; a colour or a normal where its three
// columns stand in order.
Status XyzReader::State::columnsFromNames(const std::vector<std::string>& names) {
  if (names.size() != layout.columns)
    return fail(fmt::format("{} values under {} column names", layout.columns, names.size()));
  const auto find = [&](std::initializer_list<std::string_view> options) {
    for (std::string_view o : options) {
      const auto it = std::find(names.begin(), names.end(), o);
      if (it != names.end()) return static_cast<int>(it - names.begin());
    }
    return -1;
  };
  layout.x = find({"x", "easting"});
  layout.y = find({"y", "northing"});
  layout.z = find({"z", "elevation", "height"});
  if (layout.x < 0 || layout.y < 0 || layout.z < 0)
    return badInputAtLine(source->name(), 1, "the column names have no x, y and z");
  const int red = find({"r", "red"}), green = find({"g", "green"}), blue = find({"b", "blue"});
  if (red >= 0 && green == red + 1 && blue == red + 2) layout.red = red;
  const int nx = find({"nx", "normal_x", "normalx"}), ny = find({"ny", "normal_y", "normaly"}),
            nz = find({"nz", "normal_z", "normalz"});
  if (nx >= 0 && ny == nx + 1 && nz == nx + 2) layout.normal = nx;
  return {};
}

// The columns by their count, without names.
Status XyzReader::State::columnsFromCount() {
  switch (layout.columns) {
    case 3:
    case 4:
      break;  // x y z [intensity]
    case 6: {
      // Colour or normal: colours are whole numbers and not all of them 0 or 1.
      bool whole = true, aboveOne = false;
      for (int c = 3; c < 6; ++c) {
        whole = whole && value(c) == std::floor(value(c));
        aboveOne = aboveOne || value(c) > 1;
      }
      (whole && aboveOne ? layout.red : layout.normal) = 3;
      break;
    }
    case 7:
      layout.red = 4;
      break;  // PTS: x y z intensity r g b
    case 9:
      layout.red = 3;
      layout.normal = 6;
      break;
    default:
      return fail(
          fmt::format("{} columns: expected 3 (x y z), 4 (x y z i), 6 (x y z r g b, or "
                      "x y z nx ny nz), 7 (x y z i r g b) or 9 (x y z r g b nx ny nz), "
                      "or a first line of column names",
                      layout.columns));
  }
  return {};
}

// 0–1 floats: all within [0, 1] and one at least a fraction (0 0 1 is ambiguous: 0–255).
bool XyzReader::State::colorsInUnits() const {
  bool within = true, fraction = false;
  for (int c = layout.red; c < layout.red + 3; ++c) {
    within = within && value(c) >= 0 && value(c) <= 1;
    fraction = fraction || value(c) != std::floor(value(c));
  }
  return within && fraction;
}

// The layout from the first line of numbers and the names before it, if any.
Result<XyzReader> XyzReader::start(std::unique_ptr<State> state) try {
  State& s = *state;
  std::vector<std::string> names;
  const Result<bool> found = s.findFirstPoint(names);
  if (!found) return found.status();
  if (!*found) return XyzReader(std::move(state));  // no points at all
  s.layout.columns = s.fields.size();
  if (s.layout.columns > 64) return s.fail(fmt::format("{} columns: at most 64", s.layout.columns));
  s.layout.hasHeader = !names.empty();
  LODFORGE_TRY(s.layout.hasHeader ? s.columnsFromNames(names) : s.columnsFromCount());
  if (s.layout.red >= 0) s.layout.unitColors = s.colorsInUnits();
  s.pending = true;
  return XyzReader(std::move(state));
} catch (const ErrorException& e) {
  return e.error;
}

Result<bool> XyzReader::next(PointBatch& batch) try {
  State& s = *state_;
  const XyzLayout& layout = s.layout;
  batch.clear();
  batch.first = s.nextPoint;
  while (batch.size() < s.batchSize) {
    if (!s.pending && !s.nextLine()) break;
    s.pending = false;
    split(s.text, layout.separator, s.fields);
    if (s.fields.size() != layout.columns)
      return s.fail(
          fmt::format("{} values where the file has {} columns", s.fields.size(), layout.columns));
    double values[64];
    for (std::size_t c = 0; c < layout.columns; ++c) {
      const std::optional<double> v = number(s.fields[c]);
      if (!v) return s.fail(fmt::format("column {}: '{}' is not a number", c + 1, s.fields[c]));
      if (!std::isfinite(*v)) return s.fail(fmt::format("column {}: not a finite number", c + 1));
      values[c] = *v;
    }
    const auto at = [&](int c) { return values[c]; };
    batch.positions.push_back({at(layout.x), at(layout.y), at(layout.z)});
    if (layout.red >= 0) {
      const double scale = layout.unitColors ? 255 : 1;
      const auto channel = [&](int c) {
        return static_cast<std::uint8_t>(std::clamp(std::lround(at(c) * scale), 0L, 255L));
      };
      batch.colors.push_back(
          {channel(layout.red), channel(layout.red + 1), channel(layout.red + 2), 255});
    }
    if (layout.normal >= 0) {
      batch.normals.push_back(normalizeOr(
          Vec3f{static_cast<float>(at(layout.normal)), static_cast<float>(at(layout.normal + 1)),
                static_cast<float>(at(layout.normal + 2))},
          Vec3f{0, 0, 1}));
    }
  }
  s.nextPoint += batch.size();
  return !batch.positions.empty();
} catch (const ErrorException& e) {
  return e.error;
}

}  // namespace lodforge
