#include "lodforge/core/units.h"

#include <cctype>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

namespace lodforge {

namespace {

// `whole`: a value that is not a whole number (a count of 1.5) is refused, not rounded.
std::optional<std::uint64_t> parseScaled(std::string_view text, double base, bool whole) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
    text.remove_suffix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
    text.remove_prefix(1);
  if (text.empty()) return std::nullopt;
  double multiplier = 1;
  // Accept "2G", "2g", "2GB", "2GiB".
  std::string_view unit = text;
  std::size_t digits = 0;
  while (digits < text.size() &&
         (std::isdigit(static_cast<unsigned char>(text[digits])) || text[digits] == '.'))
    ++digits;
  unit = text.substr(digits);
  text = text.substr(0, digits);
  if (unit.ends_with("iB") || unit.ends_with("ib"))
    unit.remove_suffix(2);
  else if (unit.size() == 2 && (unit[1] == 'B' || unit[1] == 'b'))
    unit.remove_suffix(1);
  if (unit.size() > 1) return std::nullopt;
  if (unit.size() == 1) {
    switch (std::toupper(static_cast<unsigned char>(unit[0]))) {
      case 'K':
        multiplier = base;
        break;
      case 'M':
        multiplier = base * base;
        break;
      case 'G':
        multiplier = base * base * base;
        break;
      case 'T':
        multiplier = base * base * base * base;
        break;
      case 'B':
        multiplier = 1;
        break;
      default:
        return std::nullopt;
    }
  }
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  const double scaled = value * multiplier;
  if (!std::isfinite(scaled) || scaled < 0 || scaled > 1.8e19) return std::nullopt;
  if (whole && scaled != std::floor(scaled)) return std::nullopt;
  return static_cast<std::uint64_t>(std::llround(scaled));
}

}  // namespace

std::optional<std::uint64_t> parseByteSize(std::string_view text) {
  return parseScaled(text, 1024, false);
}
std::optional<std::uint64_t> parseCount(std::string_view text) {
  return parseScaled(text, 1000, true);
}

std::string formatBytes(std::uint64_t bytes) {
  static constexpr const char* kUnits[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double value = static_cast<double>(bytes);
  int unit = 0;
  while (value >= 1024 && unit < 4) {
    value /= 1024;
    ++unit;
  }
  if (unit == 0) return fmt::format("{} B", bytes);
  return fmt::format("{:.{}f} {}", value, value < 10 ? 2 : (value < 100 ? 1 : 0), kUnits[unit]);
}

std::string formatCount(std::uint64_t count) {
  std::string digits = std::to_string(count);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

}  // namespace lodforge
