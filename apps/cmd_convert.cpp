#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"

namespace scanmatch::cli {

void add_convert_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("convert", "(not implemented yet)");
  cmd->callback([] { throw Error("convert: not implemented yet"); });
}

}  // namespace scanmatch::cli
