#include <cstdio>
#include <exception>

#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"scanmatch: LiDAR scan registration, odometry and mapping (2D and 3D)"};
  app.set_version_flag("--version", std::string("scanmatch ") + SCANMATCH_VERSION);
  app.require_subcommand(1);
  scanmatch::cli::add_info_command(app);
  scanmatch::cli::add_convert_command(app);
  scanmatch::cli::add_simulate_command(app);
  scanmatch::cli::add_register_command(app);
  scanmatch::cli::add_eval_command(app);
  scanmatch::cli::add_odometry_command(app);
  scanmatch::cli::add_bench_command(app);
  scanmatch::cli::add_report_command(app);
  scanmatch::cli::add_map2d_command(app);
  scanmatch::cli::add_bench2d_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a command that ended early on purpose (Ctrl-C: 130)
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const scanmatch::Error& e) {
    std::fprintf(stderr, "scanmatch: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scanmatch: internal error: %s\n", e.what());
    return 2;
  }
  return 0;
}
