#include "scanmatch/odometry/run2d.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/progress.hpp"
#include "scanmatch/io/bag/bag_sequence.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/line_writer.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/odometry/config_io.hpp"
#include "scanmatch/sim/simulator.hpp"

namespace scanmatch {
namespace {

namespace fs = std::filesystem;

Pose to_pose3(const Pose2& T) {
  return from_xyz_rpy(T.translation().x(), T.translation().y(), 0, 0, 0, pose2_angle(T));
}

nlohmann::ordered_json error_json(const RelativeError2D& e) {
  return {{"step", e.step},
          {"pairs", e.pairs},
          {"mean_translation_mm", 1000 * e.mean_translation},
          {"median_translation_mm", 1000 * e.median_translation},
          {"max_translation_mm", 1000 * e.max_translation},
          {"mean_rotation_deg", e.mean_rotation * 180 / M_PI},
          {"median_rotation_deg", e.median_rotation * 180 / M_PI},
          {"failure_rate", e.failure_rate}};
}

}  // namespace

Scans2D load_scans_2d(const std::string& spec, const SequenceOptions& options,
                      std::size_t max_scans) {
  Scans2D out;
  if (is_simulator_spec(spec)) {
    sim::SimOptions o = options.simulator;
    o.preset = spec.substr(4);
    if (max_scans > 0) o.frames = max_scans;
    const sim::Simulator simulator(o);
    if (!simulator.sensor().is_2d())
      throw Error(spec + ": not a 2D preset (the 2D preset is room-2d)");
    for (std::size_t i = 0; i < simulator.size(); ++i) out.scans.push_back(simulator.scan_2d(i));
    out.has_reference = true;
    if (o.motion_distortion) out.rotation_period = simulator.sensor().frame_period();
    out.description = fmt::format("{} (simulated, seed {})", spec, o.seed);
    return out;
  }
  if (!fs::exists(spec))
    throw Error(spec + ": no such input (a CARMEN log, a 2D data set, a bag or sim:PRESET)");
  if (is_bag_path(spec)) {
    out.scans = read_bag_laser_scans(spec, options.topic, max_scans);
    if (out.scans.empty()) throw Error(spec + ": the topic holds no laser scans");
    out.description = spec;
    return out;
  }
  std::string path = spec;
  if (fs::is_directory(spec)) {
    path = (fs::path(spec) / "scans.log").string();
    if (!fs::exists(path)) throw Error(spec + ": a folder without scans.log (not a 2D data set)");
  }
  CarmenLog log = read_carmen_log(path);
  if (log.scans.empty()) throw Error(path + ": the log holds no laser scans");
  if (max_scans > 0 && log.scans.size() > max_scans) log.scans.resize(max_scans);
  out.scans = std::move(log.scans);
  for (const LaserScan2D& s : out.scans)
    if (!s.pose.isZero()) out.has_reference = true;
  out.description = path;
  return out;
}

Map2DSummary run_map2d(const Scans2D& input, const std::string& run_folder,
                       const Map2DRunOptions& options) {
  std::error_code ec;
  fs::create_directories(run_folder, ec);
  if (ec) throw Error(run_folder + ": cannot create the run folder: " + ec.message());
  const auto file = [&](const std::string& name) { return (fs::path(run_folder) / name).string(); };
  Mapper2D mapper(options.mapper);
  OccupancyGrid grid(options.grid), reference_grid(options.grid);
  TrajectoryWriter poses(file("poses_tum.txt"), TrajectoryFormat::kTum);
  LineWriter timing(file("timing.csv"));
  timing.line("scan,ms,iterations,points,pairs,error_m,bridged");

  Map2DSummary summary;
  summary.has_reference = input.has_reference;
  std::vector<Pose2> estimate, reference;
  Trajectory reference_trajectory;
  ProgressReporter progress("map2d", input.scans.size(), "scans", options.quiet);
  double total_ms = 0.0;
  for (std::size_t i = 0; i < input.scans.size(); ++i) {
    if (options.stop && options.stop->load()) {
      summary.interrupted = true;
      break;
    }
    const LaserScan2D& laser = input.scans[i];
    const double miss_range =
        options.miss_range > 0.0 ? std::min<double>(options.miss_range, laser.max_range) : 0.0;
    Scan2D scan =
        scan_from_laser(laser, options.mapper.min_range, miss_range, input.rotation_period);
    if (options.miss_range <= 0.0) scan.misses.clear();
    const Pose2 pose = mapper.add_scan(scan, laser.timestamp);
    const Scan2DStats& s = mapper.last_stats();
    estimate.push_back(pose);
    reference.push_back(pose2(laser.pose));
    poses.write(to_pose3(pose), laser.timestamp);
    char row[512];
    std::snprintf(row, sizeof row, "%zu,%.4f,%d,%zu,%zu,%.6f,%d", i, s.ms, s.iterations, s.points,
                  s.pairs, s.error, s.bridged ? 1 : 0);
    timing.line(row);
    // A trajectory that ran away (a failed method on hard data) can need more cells than the
    // grid allows: the run goes on and keeps its poses, without that map.
    const auto insert = [&](OccupancyGrid& g, std::string& error, const Pose2& at) {
      if (!error.empty()) return;
      try {
        g.insert_scan(at, mapper.last_scan().points, scan.misses);
      } catch (const Error& e) {
        error = e.what();
      }
    };
    insert(grid, summary.map_error, pose);
    if (options.reference_map && input.has_reference)
      insert(reference_grid, summary.reference_map_error,
             reference.front().inverse() * reference.back());
    reference_trajectory.poses.push_back(to_pose3(reference.front().inverse() * reference.back()));
    reference_trajectory.timestamps.push_back(laser.timestamp);
    summary.bridged += s.bridged;
    summary.max_ms = std::max(summary.max_ms, s.ms);
    total_ms += s.ms;
    progress.update(i + 1);
  }
  progress.finish();
  summary.scans = estimate.size();
  if (summary.scans > 1) {
    summary.mean_ms = total_ms / static_cast<double>(summary.scans - 1);
    summary.scans_per_second = 1000.0 / std::max(summary.mean_ms, 1e-9);
  }
  if (input.has_reference && !reference_trajectory.poses.empty()) {
    write_trajectory(file("poses_reference_tum.txt"), reference_trajectory, TrajectoryFormat::kTum);
    if (summary.scans > 1) summary.one_step = relative_pose_error_2d(reference, estimate, 1);
    if (summary.scans > 10) summary.ten_steps = relative_pose_error_2d(reference, estimate, 10);
  }
  if (summary.scans > 0 && summary.map_error.empty()) {
    grid.crop_to_observed();
    grid.write_map_server(file("map.pgm"));
    grid.write_png(file("map.png"));
  }
  if (summary.scans > 0 && options.reference_map && input.has_reference &&
      summary.reference_map_error.empty()) {
    reference_grid.crop_to_observed();
    reference_grid.write_map_server(file("map_reference.pgm"));
    reference_grid.write_png(file("map_reference.png"));
  }
  const Registration2DOptions& r = options.mapper.registration;
  nlohmann::ordered_json j;
  j["input"] = input.description;
  j["method"] = r.method;
  j["options"] = {
      {"initial_guess", options.mapper.constant_velocity ? "constant-velocity" : "identity"},
      {"max_iterations", r.max_iterations},
      {"tolerance", r.tolerance},
      {"max_correspondence_distance", r.max_correspondence_distance},
      {"coarse_rotation", r.coarse_rotation},
      {"coarse_translation", r.coarse_translation},
      {"subsample_projection", r.subsample_projection},
      {"sparse_step", r.sparse_step},
      {"sparse_line_radius", r.sparse_line_radius},
      {"path_max_step", r.path_rules.max_step},
      {"path_shared_rows", to_string(r.path_rules.shared)},
      {"path_max_run", r.path_rules.max_run},
      {"sparse_keep_fraction", r.sparse_keep_fraction},
      {"sparse_min_pairs", r.sparse_min_pairs},
      {"pl_line_radius", r.pl_line_radius},
      {"search_window", r.search_window},
      {"search_angle_deg", r.search_angle * 180 / M_PI},
      {"deskew", options.mapper.deskew && input.rotation_period > 0.0},
      {"rotation_period_s", input.rotation_period},
      {"grid_resolution", options.grid.resolution},
      {"miss_range", options.miss_range}};
  j["scans"] = summary.scans;
  j["bridged"] = summary.bridged;
  j["interrupted"] = summary.interrupted;
  j["mean_ms"] = summary.mean_ms;
  j["max_ms"] = summary.max_ms;
  j["scans_per_second"] = summary.scans_per_second;
  if (!summary.map_error.empty()) j["map_error"] = summary.map_error;
  if (summary.one_step.pairs > 0) j["relative_error_1"] = error_json(summary.one_step);
  if (summary.ten_steps.pairs > 0) j["relative_error_10"] = error_json(summary.ten_steps);
  write_file_atomic(file("summary.json"), j.dump(2) + "\n");
  write_file_atomic(file("config.json"), map2d_config_to_json(options));
  return summary;
}

}  // namespace scanmatch
