// `scanmatch bench2d`: the 2D paper's Table 1 on simulated Neato scan pairs and the relative pose
// error of scan-to-scan mapping on CARMEN logs (scanmatch/benchmark/benchmark2d.hpp).

#include <fmt/format.h>

#include <cstdio>

#include "apps/commands.hpp"
#include "scanmatch/benchmark/benchmark2d.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"

namespace scanmatch::cli {

void add_bench2d_command(CLI::App& app) {
  auto o = std::make_shared<Benchmark2DOptions>();
  auto* cmd = app.add_subcommand(
      "bench2d", "2D scan matching: the paper's Table 1 on simulated pairs, CARMEN log errors");
  cmd->add_option("--pairs", o->pairs, "Simulated scan pairs (0: none)")->capture_default_str();
  cmd->add_option("--max-translation", o->max_translation, "Largest offset of a pair, m")
      ->capture_default_str();
  cmd->add_option("--max-rotation", o->max_rotation_deg, "Largest rotation of a pair, deg")
      ->capture_default_str();
  cmd->add_option("--method", o->methods,
                  "Methods: " + registration_2d_method_list() + ", " + kSparseIcpPaper +
                      " (sparse-icp with the paper's settings) and " + kPlIcpFitted +
                      " (pl-icp with sparse-icp's fitted lines); default: all");
  cmd->add_option("--log", o->logs, "CARMEN logs to map scan to scan (.log or .log.gz)");
  cmd->add_option("--search-window", o->search_window,
                  "Add variants with the correlative search over +- this many m (0: none)")
      ->capture_default_str();
  cmd->add_option("--out", o->out, "Write the tables to OUT/planar_tables.md");
  cmd->add_flag("--quiet", o->quiet, "No progress");
  cmd->callback([o] {
    // Tables are printed as they are done: a log's can take minutes.
    run_benchmark2d(*o, [](const std::string& table) {
      fmt::print("{}", table);
      std::fflush(stdout);
    });
  });
}

}  // namespace scanmatch::cli
