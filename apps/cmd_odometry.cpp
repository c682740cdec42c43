#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"

namespace scanmatch::cli {

// Placeholder: being written (see the open issues).
void add_odometry_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("odometry", "(not yet available)");
  cmd->callback([] { throw Error("'scanmatch odometry' is not implemented yet"); });
}

}  // namespace scanmatch::cli
