#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"

namespace scanmatch::cli {

// Placeholder: being written (see the open issues).
void add_map2d_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("map2d", "(not yet available)");
  cmd->callback([] { throw Error("'scanmatch map2d' is not implemented yet"); });
}

}  // namespace scanmatch::cli
