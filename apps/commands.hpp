#pragma once
// One function per subcommand; each lives in its own cmd_<name>.cpp and only parses options and
// calls the library. Handlers throw scanmatch::Error on failure; main prints it as one line.

#include <CLI/CLI.hpp>

namespace scanmatch::cli {

void add_info_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_register_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_odometry_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_report_command(CLI::App& app);
void add_map2d_command(CLI::App& app);
void add_bench2d_command(CLI::App& app);

}  // namespace scanmatch::cli
