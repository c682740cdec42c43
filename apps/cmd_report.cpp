#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"

namespace scanmatch::cli {

// Placeholder: being written (see the open issues).
void add_report_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("report", "(not yet available)");
  cmd->callback([] { throw Error("'scanmatch report' is not implemented yet"); });
}

}  // namespace scanmatch::cli
