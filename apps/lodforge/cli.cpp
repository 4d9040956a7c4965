#include "cli.h"

#include <fmt/format.h>

#include "lodforge/core/units.h"

namespace lodforge::cli {

CLI::Option* addCountOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                            const std::string& description) {
  return app
      .add_option_function<std::string>(
          name,
          [&target, name](const std::string& text) {
            const auto value = parseCount(text);
            if (!value)
              throw CLI::ValidationError(name, "expected a count such as 5000, 10K, 100M or 1G");
            target = *value;
          },
          description)
      ->type_name("N");
}

CLI::Option* addByteSizeOption(CLI::App& app, const std::string& name, std::uint64_t& target,
                               const std::string& description) {
  return app
      .add_option_function<std::string>(
          name,
          [&target, name](const std::string& text) {
            const auto value = parseByteSize(text);
            if (!value) throw CLI::ValidationError(name, "expected a size such as 512M or 2G");
            target = *value;
          },
          description)
      ->type_name("SIZE");
}

void say(const Global& global, const std::string& text) {
  if (global.verbosity >= 0) fmt::print("{}\n", text);
}

void detail(const Global& global, const std::string& text) {
  if (global.verbosity > 0) fmt::print(stderr, "{}\n", text);
}

}  // namespace lodforge::cli
