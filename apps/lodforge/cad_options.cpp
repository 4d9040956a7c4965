#include "cad_options.h"

#include <charconv>

#include <fmt/format.h>

namespace lodforge::cli {

void addCadOptions(CLI::App& sub, CadCommand& options) {
  sub.add_option("--deflection", options.deflection,
                 "CAD tessellation: largest chord error, relative to each part's size (0.001) "
                 "or a length (0.1mm, 2cm, 0.05m)")
      ->capture_default_str();
  sub.add_option("--angle", options.angle,
                 "CAD tessellation: largest angle in degrees between neighbouring triangles")
      ->capture_default_str();
  sub.add_option("--code-page", options.codePage,
                 "STEP: the code page of names that are neither UTF-8 nor escaped (CP1251, "
                 "CP1252, SJIS, GB, ...)");
  sub.add_flag("--hidden", options.hidden,
               "CAD: keep the parts the file hides (invisible products, hidden layers); "
               "without it they are left out");
}

Result<CadReadOptions> cadOptions(const CadCommand& options, const Global& global) {
  CadReadOptions cad;
  cad.listLost = global.verbosity > 0;
  cad.angleDegrees = options.angle;
  cad.codePage = options.codePage;
  cad.hidden = options.hidden;
  const std::string& text = options.deflection;
  double value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  const std::string_view unit(end, text.data() + text.size());
  const auto bad = [&] {
    return Error{ErrorKind::kUsage,
                 fmt::format("--deflection {}: give a fraction of each part's size (0.001) or a "
                             "positive length with its unit (0.1mm, 2cm, 0.05m)",
                             text)};
  };
  if (error != std::errc{} || !(value > 0)) return bad();
  if (unit.empty()) {
    cad.deflection = value;
  } else if (unit == "m" || unit == "cm" || unit == "mm") {
    cad.absoluteDeflection = true;
    cad.deflection = value * (unit == "m" ? 1.0 : unit == "cm" ? 0.01 : 0.001);
  } else {
    return bad();
  }
  return cad;
}

}  // namespace lodforge::cli
