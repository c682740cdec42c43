// `scanmatch bench`: every method on every sequence in one run, on identical frames, and the
// papers' tables from the results, as Markdown, CSV and HTML (scanmatch/benchmark/benchmark.hpp).

#include <cstdio>
#include <string>

#include "apps/commands.hpp"
#include "scanmatch/benchmark/benchmark.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/registration/methods.hpp"

namespace scanmatch::cli {

void add_bench_command(CLI::App& app) {
  auto o = std::make_shared<BenchmarkOptions>();
  auto* cmd = app.add_subcommand(
      "bench", "Every method on every sequence in one run: the papers' tables and a report");
  cmd->add_option("--preset", o->presets,
                  "Simulator presets (default: the CTF-ICP paper's five data sets); repeat or "
                  "separate by commas")
      ->delimiter(',');
  cmd->add_option("--sequence", o->sequences,
                  "Sequences to add (folders, KITTI sequences, bags; with ground truth for ATE)");
  cmd->add_option("--reference", o->references,
                  "Ground truth of each --sequence from a trajectory file (KITTI or TUM), one per "
                  "--sequence, in order");
  cmd->add_option("--method,--methods", o->methods,
                  "Methods (default: ctf-icp icp ndt gicp vgicp loam point-to-plane "
                  "point-to-line; any of " +
                      odometry_methods_with_peers() + "); repeat or separate by commas")
      ->delimiter(',');
  cmd->add_option("--frames", o->frames, "Frames per sequence (0: all)");
  cmd->add_option("--threads", o->threads, "Threads per method")->capture_default_str();
  cmd->add_flag("!--no-ablation", o->ablation, "Skip ctf-icp --no-fine and --no-map-update");
  cmd->add_option("--data", o->data, "Where simulated data sets are kept (default OUT/data)");
  cmd->add_option("--out", o->out, "Output folder")->required();
  cmd->add_flag("--quiet", o->quiet, "No progress");
  // For scripts choosing methods: one line per method, peers this build lacks marked.
  cmd->add_flag_callback(
      "--list-methods",
      [] {
        std::printf("ctf-icp\n");
        for (const std::string& method : registration_method_names())
          std::printf("%s\n", method.c_str());
        for (const std::string& peer : known_odometry_peers()) {
          const std::string missing = missing_peer_option(peer);
          if (missing.empty())
            std::printf("%s\n", peer.c_str());
          else
            std::printf("%s not-built (%s)\n", peer.c_str(), missing.c_str());
        }
        throw CLI::Success();
      },
      "Print the methods, one a line; peers this build lacks are marked not-built");
  cmd->callback([o] {
    BenchmarkOptions options = *o;
    options.command_line = "scanmatch bench";
    for (const auto& p : o->presets) options.command_line += " --preset " + p;
    for (const auto& s : o->sequences) options.command_line += " --sequence " + s;
    for (const auto& r : o->references) options.command_line += " --reference " + r;
    for (const auto& m : o->methods) options.command_line += " --method " + m;
    if (o->frames > 0) options.command_line += " --frames " + std::to_string(o->frames);
    options.command_line += " --threads " + std::to_string(o->threads);
    if (!o->ablation) options.command_line += " --no-ablation";
    options.command_line += " --out " + o->out;
    const BenchmarkResult result = run_benchmark(std::move(options));
    std::printf("%s", result.markdown.c_str());
    std::printf("tables in %s/tables.md and tables.csv, report in %s/report.html\n", o->out.c_str(),
                o->out.c_str());
  });
}

}  // namespace scanmatch::cli
