// `scanmatch report RUNDIR... [--gt GT] [--frames SEQUENCE] --out report.html`: one
// self-contained HTML page with an interactive 3D view of the map and trajectories.

#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/run/report.hpp"

namespace scanmatch::cli {

void add_report_command(CLI::App& app) {
  struct Options {
    std::vector<std::string> runs;
    std::string ground_truth, out, title = "scanmatch odometry report";
    std::string frames, topic, three_js;
    std::uint64_t seed = 1;
    std::size_t max_points = View3DOptions{}.max_points;
    bool no_3d = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "report", "HTML report of odometry runs: tables, trajectories, errors, timing, map");
  cmd->add_option("RUNDIR", o->runs, "Run folders written by scanmatch odometry")->required();
  cmd->add_option("--gt", o->ground_truth,
                  "Ground truth (KITTI or TUM); default: each run's poses_gt.txt");
  cmd->add_option("--out", o->out, "Output HTML file")->required();
  cmd->add_option("--title", o->title, "Page title")->capture_default_str();
  cmd->add_option("--frames", o->frames,
                  "The sequence the first run read (as odometry takes it): its frames, placed by "
                  "the run's poses, make the 3D view's map (in place of a saved map.pcd)");
  cmd->add_option("--seed", o->seed, "Seed of a sim:PRESET --frames sequence")
      ->capture_default_str();
  cmd->add_option("--topic", o->topic, "Cloud topic of a bag given as --frames");
  cmd->add_option("--max-points", o->max_points, "Map points in the 3D view at most")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--three-js", o->three_js,
                  std::string("Folder of three.min.js to inline (default: $SCANMATCH_THREE_JS_DIR, "
                              "else ") +
                      kDefaultThreeJsDir + "); without it the page keeps its 2D views");
  cmd->add_flag("--no-3d", o->no_3d, "No 3D view (a page without scripts)");
  cmd->callback([o] {
    std::vector<RunFolder> runs;
    for (const auto& path : o->runs) runs.push_back(read_run_folder(path));
    std::optional<Trajectory> gt;
    if (!o->ground_truth.empty()) gt = read_trajectory(o->ground_truth);
    ReportOptions options;
    options.title = o->title;
    options.view3d.enabled = !o->no_3d;
    options.view3d.three_js_dir = o->three_js;
    options.view3d.max_points = o->max_points;
    options.view3d.frames = o->frames;
    options.view3d.sequence.topic = o->topic;
    options.view3d.sequence.simulator.seed = o->seed;
    if (!o->frames.empty() && !o->no_3d) {  // a long sequence takes a while to read again
      std::printf("3D view: rebuilding the map from the frames of %s and the poses of %s\n",
                  o->frames.c_str(), runs.front().path.c_str());
      std::fflush(stdout);
    }
    write_file_atomic(o->out, render_report(runs, gt, options));
    std::printf("report written to %s\n", o->out.c_str());
  });
}

}  // namespace scanmatch::cli
