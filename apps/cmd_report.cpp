// `scanmatch report RUNDIR... [--gt GT] --out report.html`: one self-contained HTML page.

#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/odometry/report.hpp"
#include "scanmatch/io/file_util.hpp"

namespace scanmatch::cli {

void add_report_command(CLI::App& app) {
  struct Options {
    std::vector<std::string> runs;
    std::string ground_truth, out, title = "scanmatch odometry report";
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "report", "HTML report of odometry runs: tables, trajectories, errors, timing, map");
  cmd->add_option("RUNDIR", o->runs, "Run folders written by scanmatch odometry")->required();
  cmd->add_option("--gt", o->ground_truth,
                  "Ground truth (KITTI or TUM); default: each run's poses_gt.txt");
  cmd->add_option("--out", o->out, "Output HTML file")->required();
  cmd->add_option("--title", o->title, "Page title")->capture_default_str();
  cmd->callback([o] {
    std::vector<RunFolder> runs;
    for (const auto& path : o->runs) runs.push_back(read_run_folder(path));
    std::optional<Trajectory> gt;
    if (!o->ground_truth.empty()) gt = read_trajectory(o->ground_truth);
    ReportOptions options;
    options.title = o->title;
    write_file_atomic(o->out, render_report(runs, gt, options));
    std::printf("report written to %s\n", o->out.c_str());
  });
}

}  // namespace scanmatch::cli
