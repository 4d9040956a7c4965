#include "cli.h"

#include <fmt/format.h>

#include "lodforge/core/units.h"

namespace lodforge::cli {

namespace {
// An option whose text goes through `parse`; CLI11 reports a failure as a usage error (exit 2).
CLI::Option* addParsedOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                             const std::string& description,
                             std::optional<std::uint64_t> (*parse)(std::string_view),
                             const char* expected, const char* typeName) {
  return app
      .add_option_function<std::string>(
          name,
          [&target, name, parse, expected](const std::string& text) {
            const auto value = parse(text);
            if (!value) throw CLI::ValidationError(name, expected);
            target = *value;
          },
          description)
      ->type_name(typeName);
}
}  // namespace

CLI::Option* addCountOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                            const std::string& description) {
  return addParsedOption(app, name, target, description, parseCount,
                         "expected a count such as 5000, 10K, 100M or 1G", "N");
}

CLI::Option* addByteSizeOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                               const std::string& description) {
  return addParsedOption(app, name, target, description, parseByteSize,
                         "expected a size such as 512M or 2G", "SIZE");
}

void say(const Global& global, const std::string& text) {
  if (global.verbosity >= 0) fmt::print("{}\n", text);
}

void detail(const Global& global, const std::string& text) {
  if (global.verbosity > 0) fmt::print(stderr, "{}\n", text);
}

}  // namespace lodforge::cli
