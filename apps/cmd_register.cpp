#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"

namespace scanmatch::cli {

void add_register_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("register", "(not implemented yet)");
  cmd->callback([] { throw Error("register: not implemented yet"); });
}

}  // namespace scanmatch::cli
