#include "scanmatch/run/map2d_run.hpp"

#include <atomic>
#include <filesystem>
#include <future>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/progress.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/mapping/loop_counts.hpp"
#include "scanmatch/run/run_config.hpp"
#include "scanmatch/run/run_record.hpp"

namespace scanmatch {
namespace {

namespace fs = std::filesystem;

// Scans queued for the loop closure thread before the odometry waits for it (2D scans are small;
// this absorbs a burst of verifications without holding the odometry back).
constexpr std::size_t kLoopQueueScans = 256;
// Scans queued for the loop closure thread from which the odometry's thread makes their keyframe
// steps itself (the loop closure's thread has fallen behind).
constexpr std::size_t kStepsHereFromQueued = 2;

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

nlohmann::ordered_json consistency_json(const RevisitConsistency2D& c) {
  return {{"points", c.points},
          {"revisited_share",
           c.points > 0 ? static_cast<double>(c.revisited) / static_cast<double>(c.points) : 0.0},
          {"mean_m", c.mean},
          {"median_m", c.median},
          {"p90_m", c.p90}};
}

nlohmann::ordered_json ate_json(const AbsoluteError2D& e) {
  return {{"poses", e.poses}, {"rmse_m", e.rmse}, {"mean_m", e.mean}, {"max_m", e.max}};
}

// Share of `map`'s occupied cells, moved by `alignment` (the trajectory's SE(2) alignment onto
// the reference, so that an early heading error does not count everywhere), with an occupied cell
// of `reference` within `cells` cells.
double map_agreement(const OccupancyGrid& map, const OccupancyGrid& reference, int cells,
                     const Pose2& alignment) {
  const std::vector<Eigen::Vector2d> occupied = map.occupied_cell_centres();
  if (occupied.empty()) return 0.0;
  const double r = reference.resolution();
  std::size_t near = 0;
  for (const Eigen::Vector2d& cell : occupied) {
    const Eigen::Vector2d c = alignment * cell;
    bool found = false;
    for (int dx = -cells; dx <= cells && !found; ++dx)
      for (int dy = -cells; dy <= cells && !found; ++dy)
        found = reference.occupied(c + Eigen::Vector2d(dx * r, dy * r));
    near += found;
  }
  return static_cast<double>(near) / static_cast<double>(occupied.size());
}

void write_map(const OccupancyGrid& grid, const std::string& base) {
  grid.write_map_server(base + ".pgm");
  grid.write_png(base + ".png");
}

}  // namespace

Map2DSummary run_map2d(const Scans2D& input, const std::string& run_folder,
                       const Map2DRunOptions& options) {
  create_run_folder(run_folder);
  const auto file = [&](const std::string& name) { return (fs::path(run_folder) / name).string(); };
  Mapper2D mapper(options.mapper);
  OccupancyGrid grid(options.grid), reference_grid(options.grid);
  TrajectoryWriter poses(file("poses_tum.txt"), TrajectoryFormat::kTum);
  TimingWriter<Scan2DStats> timing(file("timing.csv"));

  Map2DSummary summary;
  summary.has_reference = input.has_reference;
  // Each scan's keyframe step (LoopKeyframes2D) needs the odometry alone. It is made on the loop
  // closure's thread while that keeps up (where the odometry is the slower one: acapulco) and
  // here, on the odometry's, while it falls behind (intel's many verifications). The steps are
  // made in order either way, so the results are the same: here only once every step left to
  // the loop closure's thread is made.
  struct LoopInput {
    Scan2D scan;
    Pose2 pose = Pose2::Identity();
    bool weak_fit = false;
    bool unfit = false;  // not registered: bridged, or fit too poorly (LoopKeyframes2D::add_scan)
    std::optional<KeyframeStep2D> step;  // none: made on the loop closure's thread
  };
  struct SharedKeyframes {
    std::mutex mutex;
    std::optional<LoopKeyframes2D> keyframes;
    // Queued inputs whose step is not made yet. Read without the mutex: while it is not 0 the
    // odometry's thread leaves the steps to the other, and at 0 the other touches no step.
    std::atomic<std::size_t> left_to_thread{0};
  } shared;
  std::optional<LoopClosureRun<LoopClosure2D, LoopInput>> closure;
  if (options.loop_closure) {
    shared.keyframes.emplace(options.loop);
    closure.emplace(options.loop, options.loop_closure_thread, kLoopQueueScans,
                    [&shared](LoopClosure2D& loops, LoopInput& in) {
                      if (!in.step) {
                        const std::lock_guard<std::mutex> lock(shared.mutex);
                        in.step =
                            shared.keyframes->add_scan(in.scan, in.pose, in.weak_fit, in.unfit);
                        --shared.left_to_thread;
                      }
                      loops.add_step(in.scan, *in.step);
                    });
  }
  const Stopwatch run_time;
  // The registered scans, kept to rebuild the map from the optimized poses and to measure how
  // well revisits agree.
  std::vector<Scan2D> kept_scans;
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
    timing.write(i, laser.timestamp, s);
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
    if (closure) {
      const Scan2DStats& stats = mapper.last_stats();
      LoopInput in{mapper.last_scan(), pose, stats.weak_fit, stats.unregistered(), std::nullopt};
      if (shared.left_to_thread.load() == 0 && closure->queued() >= kStepsHereFromQueued) {
        const std::lock_guard<std::mutex> lock(shared.mutex);
        in.step = shared.keyframes->add_scan(in.scan, in.pose, in.weak_fit, in.unfit);
      } else {
        ++shared.left_to_thread;
      }
      closure->push(std::move(in));
    }
    Scan2D kept = mapper.last_scan();
    kept.misses = scan.misses;
    kept.times.clear();
    kept_scans.push_back(std::move(kept));
    if (options.reference_map && input.has_reference)
      insert(reference_grid, summary.reference_map_error,
             reference.front().inverse() * reference.back());
    reference_trajectory.poses.push_back(to_pose3(reference.front().inverse() * reference.back()));
    reference_trajectory.timestamps.push_back(laser.timestamp);
    summary.bridged += s.bridged;
    summary.open_steps_from_prior += s.open_step_from_prior;
    summary.max_ms = std::max(summary.max_ms, s.ms);
    total_ms += s.ms;
    progress.update(i + 1);
  }
  progress.finish();
  if (closure) closure->finish();
  summary.scans = estimate.size();
  if (summary.scans > 0)
    summary.wall_ms_per_scan = run_time.ms() / static_cast<double>(summary.scans);
  if (summary.scans > 1) {
    summary.mean_ms = total_ms / static_cast<double>(summary.scans - 1);
    summary.scans_per_second = 1000.0 / std::max(summary.mean_ms, 1e-9);
  }
  // Loop closure: the optimized poses, their map and the accepted loops.
  std::vector<Pose2> optimized;
  OccupancyGrid optimized_grid(options.grid);
  std::string optimized_map_error;
  nlohmann::ordered_json loops_json = nlohmann::ordered_json::array();
  std::future<void> optimized_map;  // last of these: waits for its thread before they go
  if (closure) {
    optimized = closure->loop_closure().poses();
    summary.loop_closure = closure->record(summary.scans);
    Trajectory optimized_trajectory;
    for (std::size_t i = 0; i < optimized.size(); ++i) {
      optimized_trajectory.poses.push_back(to_pose3(optimized[i]));
      optimized_trajectory.timestamps.push_back(input.scans[i].timestamp);
    }
    // The optimized map is built and written on a thread of its own while the odometry's maps
    // and metrics are worked out below: it is most of what loop closure adds after the last scan
    // (4 s of freiburg-campus's 2008 long-range scans).
    if (summary.scans > 0)
      optimized_map = std::async(std::launch::async, [&] {
        for (std::size_t i = 0; i < optimized.size() && optimized_map_error.empty(); ++i) {
          try {
            optimized_grid.insert_scan(optimized[i], kept_scans[i].points, kept_scans[i].misses);
          } catch (const Error& e) {
            optimized_map_error = e.what();
          }
        }
        if (!optimized_map_error.empty()) return;
        optimized_grid.crop_to_observed();
        write_map(optimized_grid, file("map"));
      });
    write_trajectory(file("poses_optimized_tum.txt"), optimized_trajectory, TrajectoryFormat::kTum);
    for (const Loop2D& l : closure->loop_closure().loops()) {
      if (l.outlier) continue;
      loops_json.push_back({{"from", l.from_scan},
                            {"to", l.to_scan},
                            {"from_keyframe", l.from_keyframe},
                            {"to_keyframe", l.to_keyframe},
                            {"x", l.relative.translation().x()},
                            {"y", l.relative.translation().y()},
                            {"theta", pose2_angle(l.relative)},
                            {"paired_fraction", l.paired_fraction},
                            {"error_m", l.error}});
      if (l.sliding)
        loops_json.back()["slide_direction"] = {l.slide_direction.x(), l.slide_direction.y()};
    }
    write_json_atomic(file("loops.json"), loops_json);
  }
  if (input.has_reference && !reference_trajectory.poses.empty()) {
    write_trajectory(file("poses_reference_tum.txt"), reference_trajectory, TrajectoryFormat::kTum);
    if (summary.scans > 1) summary.one_step = relative_pose_error_2d(reference, estimate, 1);
    if (summary.scans > 10) summary.ten_steps = relative_pose_error_2d(reference, estimate, 10);
    summary.ate_odometry = absolute_trajectory_error_2d(reference, estimate);
    summary.all_pairs_odometry = all_pairs_relative_error_2d(reference, estimate);
    if (closure) {
      summary.ate_optimized = absolute_trajectory_error_2d(reference, optimized);
      summary.all_pairs_optimized = all_pairs_relative_error_2d(reference, optimized);
    }
  }
  const bool reference_written = summary.scans > 0 && options.reference_map &&
                                 input.has_reference && summary.reference_map_error.empty();
  if (reference_written) {
    reference_grid.crop_to_observed();
    write_map(reference_grid, file("map_reference"));
  }
  // map.* is the best map there is: the optimized one with loop closure, else the odometry's.
  if (summary.scans > 0 && summary.map_error.empty()) {
    grid.crop_to_observed();
    write_map(grid, file(closure ? "map_odometry" : "map"));
    if (reference_written) {
      const double agreement = map_agreement(
          grid, reference_grid, 2, reference.front().inverse() * summary.ate_odometry.alignment);
      (closure ? summary.map_agreement_odometry : summary.map_agreement) = agreement;
    }
  }
  if (closure && summary.scans > 0) {
    optimized_map.get();  // rethrows what writing it threw
    if (optimized_map_error.empty()) {
      if (reference_written)
        summary.map_agreement =
            map_agreement(optimized_grid, reference_grid, 2,
                          reference.front().inverse() * summary.ate_optimized.alignment);
    } else {
      summary.map_error = optimized_map_error;
    }
  }
  // Needs no reference: how far apart the walls of revisits lie.
  if (summary.scans > 0) {
    summary.consistency_odometry = revisit_consistency_2d(kept_scans, estimate);
    if (closure && optimized.size() == kept_scans.size())
      summary.consistency_optimized = revisit_consistency_2d(kept_scans, optimized);
    if (input.has_reference)
      summary.consistency_reference = revisit_consistency_2d(kept_scans, reference);
  }
  // The options are the configuration as config.json holds it (one description:
  // run/run_config_fields.hpp); what the input decided beside them is said apart.
  const std::string config = map2d_config_to_json(options);
  nlohmann::ordered_json j;
  j["kind"] = kMap2DRunKind;
  j["input"] = input.description;
  j["rotation_period_s"] = input.rotation_period;
  j["deskewed"] = options.mapper.deskew && input.rotation_period > 0.0;
  j["method"] = options.mapper.registration.method;
  j["options"] = nlohmann::ordered_json::parse(config);
  j["scans"] = summary.scans;
  j["bridged"] = summary.bridged;
  j["open_steps_from_prior"] = summary.open_steps_from_prior;
  j["interrupted"] = summary.interrupted;
  j["mean_ms"] = summary.mean_ms;
  j["max_ms"] = summary.max_ms;
  j["scans_per_second"] = summary.scans_per_second;
  j["wall_ms_per_scan"] = summary.wall_ms_per_scan;
  if (!summary.map_error.empty()) j["map_error"] = summary.map_error;
  if (summary.one_step.pairs > 0) j["relative_error_1"] = error_json(summary.one_step);
  if (summary.ten_steps.pairs > 0) j["relative_error_10"] = error_json(summary.ten_steps);
  if (summary.ate_odometry.poses > 0) {
    j["ate"] = ate_json(summary.loop_closure ? summary.ate_optimized : summary.ate_odometry);
    j["ate_odometry"] = ate_json(summary.ate_odometry);
  }
  if (summary.all_pairs_odometry.pairs > 0) {
    j["relative_error_all_pairs"] =
        error_json(summary.loop_closure ? summary.all_pairs_optimized : summary.all_pairs_odometry);
    j["relative_error_all_pairs_odometry"] = error_json(summary.all_pairs_odometry);
  }
  if (summary.map_agreement >= 0) j["map_agreement"] = summary.map_agreement;
  if (summary.map_agreement_odometry >= 0)
    j["map_agreement_odometry"] = summary.map_agreement_odometry;
  if (summary.consistency_odometry.points > 0) {
    j["revisit_consistency"] = consistency_json(
        summary.loop_closure ? summary.consistency_optimized : summary.consistency_odometry);
    if (summary.loop_closure)
      j["revisit_consistency_odometry"] = consistency_json(summary.consistency_odometry);
    if (summary.consistency_reference.points > 0)
      j["revisit_consistency_reference"] = consistency_json(summary.consistency_reference);
  }
  if (summary.loop_closure) j["loop_closure"] = loop_closure_json(*summary.loop_closure, "scan");
  write_json_atomic(file("summary.json"), j);
  write_file_atomic(file("config.json"), config);
  return summary;
}

}  // namespace scanmatch
