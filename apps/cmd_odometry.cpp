// `scanmatch odometry SEQUENCE --method NAME --out RUNDIR`: poses, timing, summary and map of a
// whole sequence (folder, KITTI sequence, simulator data set, sim:PRESET or a bag's cloud topic).

#include <fmt/format.h>

#include "apps/commands.hpp"
#include "apps/config_options.hpp"
#include "apps/interrupt.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/run/odometry_run.hpp"
#include "scanmatch/run/run_config.hpp"
#include "scanmatch/sim/open_sequence.hpp"

namespace scanmatch::cli {
namespace {

struct OdometryCommand {
  std::string sequence, out, config_file, topic, reference;
  std::size_t frames = 0;
  std::uint64_t seed = 1;
  bool quiet = false;
  OdometryRunConfig config;  ///< the flags of the one description, for config.json
};

void run_command(OdometryCommand& c, const CLI::App& cmd) {
  // Options given on the command line win over the --config file.
  OdometryRunConfig given = c.config;
  if (!c.config_file.empty())
    given = override_given_flags(read_odometry_run_config(c.config_file), c.config,
                                 [&](const std::string& flag) { return cmd.count(flag) > 0; });
  OdometryConfig& config = given.odometry;

  SequenceOptions input;
  input.topic = c.topic;
  input.reference = c.reference;
  input.simulator.seed = c.seed;
  if (c.frames > 0) input.simulator.frames = c.frames;
  const auto source = open_sequence(c.sequence, input);
  RunOptions run = given.output;
  run.out_dir = c.out;
  run.max_frames = c.frames;
  run.quiet = c.quiet;
  RunSummary summary;
  {
    const InterruptFlag interrupt;
    run.stop = interrupt.flag();
    summary = run_odometry(*source, config, run);
  }
  std::string accuracy;
  if (const auto& ate = summary.ate)
    accuracy = ate->path_length > 0.0
                   ? fmt::format("ATE {:.3f} m RMSE, {:.3f} % of the {:.1f} m path", ate->rmse,
                                 ate->rmse_percent_of_path, ate->path_length)
                   : fmt::format("still sensor: final drift {:.4f} m, max {:.4f} m",
                                 ate->final_drift, ate->max);
  if (!c.quiet) {
    std::printf("%s on %s: %zu frames, %.1f frames/s (pipeline %.2f ms/frame mean, %.2f max)%s\n",
                summary.method.c_str(), summary.source.c_str(), summary.frames,
                summary.frames_per_second, summary.stage("total").mean_ms,
                summary.stage("total").max_ms, summary.interrupted ? ", interrupted" : "");
    std::printf("stages (mean ms): preprocess %.2f, coarse %.2f, fine %.2f, map update %.2f\n",
                summary.stage("preprocess").mean_ms, summary.stage("coarse").mean_ms,
                summary.stage("fine").mean_ms, summary.stage("map_update").mean_ms);
    if (summary.bridged_frames > 0)
      std::printf("%zu frames bridged by the motion prior\n", summary.bridged_frames);
    if (!accuracy.empty())
      std::printf("%s%s\n", accuracy.c_str(), summary.loop_closure ? " (odometry)" : "");
    if (summary.loop_closure) {
      const auto& l = *summary.loop_closure;
      std::printf(
          "loop closure: %zu keyframes, %zu candidates, %zu verified, %zu accepted (%zu "
          "outliers), %.2f ms per frame %s; the run took %.2f ms per frame",
          l.counts.keyframes, l.counts.candidates, l.counts.verified, l.accepted, l.counts.outliers,
          l.ms_per_item, l.thread ? "on its own thread" : "inline", summary.wall_ms_per_frame);
      if (l.thread) std::printf(", %.2f of it waiting for loop closure", l.wait_ms_per_item);
      std::printf("\n");
      if (const auto& ate = summary.ate_optimized; ate && ate->path_length > 0.0)
        std::printf("ATE loop-closed %.3f m RMSE, %.3f %% of the %.1f m path\n", ate->rmse,
                    ate->rmse_percent_of_path, ate->path_length);
    }
    std::printf("results in %s\n", c.out.c_str());
  }
  if (summary.interrupted) throw CLI::RuntimeError(130);
}

}  // namespace

void add_odometry_command(CLI::App& app) {
  auto c = std::make_shared<OdometryCommand>();
  auto* cmd = app.add_subcommand(
      "odometry", "LiDAR odometry over a sequence: poses, timing, summary and optionally a map");
  cmd->add_option("SEQUENCE", c->sequence,
                  "A folder of PCD/PLY/BIN frames, a KITTI sequence, a simulated data set, "
                  "sim:PRESET or a ROS bag (.bag, .db3, .mcap)")
      ->required();
  cmd->add_option("--out", c->out, "Run folder (created)")->required();
  cmd->add_option(
      "--topic", c->topic,
      "Bags (.bag, .db3, .mcap): the PointCloud2 or Livox topic (default: the only one)");
  cmd->add_option("--config", c->config_file,
                  "JSON configuration (as written to RUNDIR/config.json); options given here win");
  cmd->add_option("--frames", c->frames, "Process at most this many frames (0: all)");
  cmd->add_option("--seed", c->seed, "Seed of sim:PRESET sequences")->capture_default_str();
  cmd->add_option("--reference", c->reference,
                  "Ground truth for the ATE from this trajectory file (KITTI or TUM, one pose per "
                  "frame) instead of the sequence's own");
  add_config_options(cmd, c->config);
  cmd->get_option("--method")->description("One of: " + odometry_methods_with_peers());
  cmd->add_flag("--quiet", c->quiet, "No progress and no summary lines");
  cmd->callback([c, cmd] { run_command(*c, *cmd); });
}

}  // namespace scanmatch::cli
