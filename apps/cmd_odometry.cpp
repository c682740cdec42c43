// `scanmatch odometry SEQUENCE --method NAME --out RUNDIR`: poses, timing, summary and map of a
// whole sequence (folder, KITTI sequence, simulator data set or sim:PRESET).

#include <fmt/format.h>

#include <filesystem>

#include "apps/commands.hpp"
#include "apps/interrupt.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/odometry/config_io.hpp"
#include "scanmatch/odometry/run.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch::cli {
namespace {

struct OdometryCommand {
  std::string sequence, out, config_file;
  std::size_t frames = 0;
  std::uint64_t seed = 1;
  bool quiet = false, no_fine = false, no_map_update = false, no_deskew = false;
  RunOptions run;
  OdometryConfig config;
};

void run_command(OdometryCommand& c, const CLI::App& cmd) {
  // Options given on the command line win over the --config file.
  OdometryConfig config = c.config;
  if (!c.config_file.empty()) {
    config = read_odometry_config(c.config_file, OdometryConfig{});
    const auto given = [&](const char* name) { return cmd.count(name) > 0; };
    if (given("--method")) config.method = c.config.method;
    if (given("--voxel")) config.voxel_size = c.config.voxel_size;
    if (given("--ndt-resolution")) config.ndt_resolution = c.config.ndt_resolution;
    if (given("--voxel-resolution"))
      config.registration.voxel_resolution = c.config.registration.voxel_resolution;
    if (given("--map-voxel")) config.map_voxel_size = c.config.map_voxel_size;
    if (given("--merge-threshold")) config.merge_threshold = c.config.merge_threshold;
    if (given("--map-radius")) config.map_radius = c.config.map_radius;
    if (given("--max-iterations")) config.fine_max_iterations = c.config.fine_max_iterations;
    if (given("--degeneracy-ratio")) config.degeneracy_ratio = c.config.degeneracy_ratio;
    if (given("--threads")) config.threads = c.config.threads;
  }
  if (c.no_fine) config.fine_stage = false;
  if (c.no_map_update) config.map_update = false;
  if (c.no_deskew) config.deskew = false;
  config.registration.solver.num_threads = config.threads;

  sim::SimOptions sim_options;
  sim_options.seed = c.seed;
  if (c.frames > 0) sim_options.frames = c.frames;
  const bool simulated = c.sequence.rfind("sim:", 0) == 0;
  if (!simulated && !std::filesystem::exists(c.sequence))
    throw Error(c.sequence + ": no such sequence (a folder, a KITTI sequence or sim:PRESET)");
  const auto source = sim::open_sequence(c.sequence, sim_options);
  c.run.out_dir = c.out;
  c.run.max_frames = c.frames;
  c.run.quiet = c.quiet;
  RunSummary summary;
  {
    const InterruptFlag interrupt;
    c.run.stop = interrupt.flag();
    summary = run_odometry(*source, config, c.run);
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
                summary.frames_per_second, summary.total.mean_ms, summary.total.max_ms,
                summary.interrupted ? ", interrupted" : "");
    std::printf("stages (mean ms): preprocess %.2f, coarse %.2f, fine %.2f, map update %.2f\n",
                summary.preprocess.mean_ms, summary.coarse.mean_ms, summary.fine.mean_ms,
                summary.map_update.mean_ms);
    if (summary.bridged_frames > 0)
      std::printf("%zu frames bridged by the motion prior\n", summary.bridged_frames);
    if (!accuracy.empty()) std::printf("%s\n", accuracy.c_str());
    std::printf("results in %s\n", c.out.c_str());
  }
  if (summary.interrupted) throw CLI::RuntimeError(130);
}

}  // namespace

void add_odometry_command(CLI::App& app) {
  auto c = std::make_shared<OdometryCommand>();
  auto* cmd = app.add_subcommand(
      "odometry", "LiDAR odometry over a sequence: poses, timing, summary and optionally a map");
  std::string methods = "ctf-icp";
  for (const auto& m : registration_method_names()) methods += ", " + m;
  OdometryConfig& o = c->config;
  cmd->add_option("SEQUENCE", c->sequence,
                  "A folder of PCD/PLY/BIN frames, a KITTI sequence, a simulated data set or "
                  "sim:PRESET")
      ->required();
  cmd->add_option("--out", c->out, "Run folder (created)")->required();
  cmd->add_option("--method", o.method, "One of: " + methods)->capture_default_str();
  cmd->add_option("--config", c->config_file,
                  "JSON configuration (as written to RUNDIR/config.json); options given here win");
  cmd->add_option("--frames", c->frames, "Process at most this many frames (0: all)");
  cmd->add_option("--seed", c->seed, "Seed of sim:PRESET sequences")->capture_default_str();
  cmd->add_option("--threads", o.threads, "Threads (1 for fair comparisons)")
      ->capture_default_str();
  cmd->add_option("--voxel", o.voxel_size, "Downsampling voxel, m")->capture_default_str();
  cmd->add_option("--ndt-resolution", o.ndt_resolution, "ctf-icp: the coarse stage's NDT grid, m")
      ->capture_default_str();
  cmd->add_option("--voxel-resolution", o.registration.voxel_resolution,
                  "The ndt and vgicp methods: their Gaussian voxel grid, m")
      ->capture_default_str();
  cmd->add_option("--map-voxel", o.map_voxel_size, "Global Gaussian map voxel, m")
      ->capture_default_str();
  cmd->add_option("--merge-threshold", o.merge_threshold,
                  "New points a map voxel collects before it is merged")
      ->capture_default_str();
  cmd->add_option("--map-radius", o.map_radius, "Map voxels farther than this are dropped, m")
      ->capture_default_str();
  cmd->add_option("--max-iterations", o.fine_max_iterations, "Fine stage Gauss-Newton steps")
      ->capture_default_str();
  cmd->add_option("--degeneracy-ratio", o.degeneracy_ratio,
                  "Eigenvalue ratio below which a direction keeps the prior (0: off)")
      ->capture_default_str();
  cmd->add_flag("--no-fine", c->no_fine, "Ablation: coarse NDT stage only");
  cmd->add_flag("--no-map-update", c->no_map_update,
                "Ablation: fine stage against the previous frame, no global map");
  cmd->add_flag("--no-deskew", c->no_deskew, "Do not correct motion distortion");
  cmd->add_flag("--save-map", c->run.write_map, "Write RUNDIR/map.pcd (or .ply)");
  cmd->add_option("--map-format", c->run.map_format, "pcd or ply")->capture_default_str();
  cmd->add_option("--map-export-voxel", c->run.map_voxel_size, "Exported map voxel, m")
      ->capture_default_str();
  cmd->add_option("--map-export-radius", c->run.map_export_radius,
                  "Export only points within this radius of the last pose, m (0: all)");
  cmd->add_flag("--quiet", c->quiet, "No progress and no summary lines");
  cmd->callback([c, cmd] { run_command(*c, *cmd); });
}

}  // namespace scanmatch::cli
