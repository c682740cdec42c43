#pragma once
// Command-line options from the configuration's one description (config/fields.hpp and each
// module's config/*_fields.hpp): every described field with a flag becomes an option bound to that
// field (a bool's "--no-" flag sets it to false).

#include <CLI/CLI.hpp>
#include <string_view>
#include <type_traits>

#include "scanmatch/run/run_config_fields.hpp"

namespace scanmatch::cli {

struct ConfigOptionAdder {
  CLI::App* cmd;
  template <typename T>
  void operator()(const char*, T& field, const char* flag, const char* help) {
    if (!flag) return;
    if constexpr (std::is_same_v<T, bool>) {
      if (std::string_view(flag).starts_with("--no-"))
        cmd->add_flag_callback(
            flag, [&field] { field = false; }, help);
      else
        cmd->add_flag(flag, field, help);
    } else if constexpr (std::is_enum_v<T>) {
      cmd->add_option_function<std::string>(
             flag, [&field](const std::string& name) { enum_from_name(name, field); }, help)
          ->default_str(enum_name(field));
    } else {
      cmd->add_option(flag, field, help)->capture_default_str();
    }
  }
  template <typename S>
  void nested(const char*, S& options) {
    describe(options, *this);
  }
};

/// Adds an option for every described field of `options` that has a flag.
template <typename Options>
void add_config_options(CLI::App* cmd, Options& options) {
  ConfigOptionAdder adder{cmd};
  describe(options, adder);
}

}  // namespace scanmatch::cli
