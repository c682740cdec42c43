// `scanmatch simulate PRESET --out DIR`: writes a simulated data set with exact ground truth.

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "apps/commands.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/sim/keyframes.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch::cli {

void add_simulate_command(CLI::App& app) {
  auto options = std::make_shared<sim::SimOptions>();
  auto out = std::make_shared<std::string>();
  auto frames = std::make_shared<std::size_t>(0);
  auto quiet = std::make_shared<bool>(false);
  auto no_distortion = std::make_shared<bool>(false);
  auto no_noise = std::make_shared<bool>(false);
  auto list = std::make_shared<bool>(false);
  auto keyframes = std::make_shared<sim::KeyframeOptions>();
  auto angle_deg = std::make_shared<double>(0.0);
  auto no_point_time = std::make_shared<bool>(false);
  std::string preset_help = "Preset:";
  for (const auto& p : sim::presets())
    preset_help +=
        fmt::format("\n  {:<22} {} ({}, {} frames)", p.name, p.description, p.sensor, p.frames);
  auto* cmd = app.add_subcommand("simulate", "Simulate a LiDAR data set with exact ground truth");
  cmd->add_option("PRESET", options->preset, preset_help);
  cmd->add_option("--out", *out, "Output folder");
  cmd->add_option("--frames", *frames, "Number of frames (default: the preset's)");
  cmd->add_option("--seed", options->seed, "Scene and noise seed")->capture_default_str();
  cmd->add_option("--sensor", options->sensor, "Sensor: mid360, avia, vlp16, hdl64, os1-64, neato");
  cmd->add_option("--trajectory", options->trajectory_file,
                  "Replay this KITTI or TUM trajectory through the preset's scene");
  cmd->add_flag("--no-motion-distortion", *no_distortion,
                "Measure every point of a frame from the frame's start pose");
  cmd->add_flag("--no-noise", *no_noise, "No range noise and no dropouts");
  cmd->add_option("--elevation-bias", options->elevation_bias_deg,
                  "3D sensors: points reported this many degrees higher in elevation than the "
                  "beams that measured them (a calibration error; odometry's "
                  "--elevation-correction takes it out)");
  cmd->add_option("--every", keyframes->every, "Keyframes: keep every Nth frame");
  cmd->add_option("--keyframe-distance", keyframes->distance,
                  "Keyframes: keep a frame once the sensor moved this many m since the last kept");
  cmd->add_option("--keyframe-distance-max", keyframes->distance_max,
                  "Keyframes: irregular steps, a random threshold in [--keyframe-distance, this] "
                  "m per keyframe (seeded by --seed)");
  cmd->add_option("--keyframe-angle", *angle_deg,
                  "Keyframes: keep a frame once the sensor turned this many degrees");
  cmd->add_option("--max-points", keyframes->max_points,
                  "Random subsample of every written frame to at most N points");
  cmd->add_flag("--no-point-time", *no_point_time,
                "Write frames without the per-point time field (like FAST-LIO keyframe folders)");
  cmd->add_flag("--list", *list, "List the presets and exit");
  cmd->add_flag("--quiet", *quiet, "No progress display");
  cmd->callback([=] {
    if (*list) {
      for (const auto& p : sim::presets())
        fmt::print("{:<22} {:<8} {:>5} frames  {}\n", p.name, p.sensor, p.frames, p.description);
      return;
    }
    if (out->empty()) throw Error("simulate: --out DIR is required");
    if (*frames > 0) options->frames = *frames;
    options->motion_distortion = !*no_distortion;
    options->noise = !*no_noise;
    const auto start = std::chrono::steady_clock::now();
    keyframes->angle = *angle_deg * M_PI / 180.0;
    keyframes->point_time = !*no_point_time;
    keyframes->seed = options->seed;
    sim::check_keyframe_options(*keyframes);
    const sim::Simulator simulator(*options);
    std::size_t written = simulator.size();
    if (keyframes->active()) {
      sim::write_keyframe_dataset(simulator, *keyframes, *out, *quiet);
      written = sim::select_keyframes(simulator, *keyframes).size();
    } else {
      sim::write_dataset(simulator, *out, *quiet);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!*quiet)
      fmt::print("{}: {} frames of {} ({} m path) in {:.1f} s ({:.0f} frames/s) -> {}\n",
                 simulator.preset().name, written, simulator.sensor().name, simulator.path_length(),
                 seconds, static_cast<double>(written) / seconds, *out);
  });
}

}  // namespace scanmatch::cli
