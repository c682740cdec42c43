#include "scanmatch/run/odometry_run.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>

#include "scanmatch/config/config_io.hpp"
#include "scanmatch/core/error.hpp"
#include "scanmatch/core/progress.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/eval/metrics_json.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/geometry/voxel_hash.hpp"
#include "scanmatch/geometry/voxel_key.hpp"
#include "scanmatch/io/cloud_io.hpp"
#include "scanmatch/io/file_util.hpp"
#include "scanmatch/io/trajectory.hpp"
#include "scanmatch/mapping/loop_counts.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"
#include "scanmatch/odometry/health.hpp"
#include "scanmatch/odometry/spin_times.hpp"
#include "scanmatch/run/run_config.hpp"
#include "scanmatch/run/run_record.hpp"

namespace scanmatch {
namespace {

// Points queued for the loop closure thread before the odometry waits for it (~24 MB of
// positions): a bound on memory, not on frames. Its candidates come in bursts at revisits, so a
// queue of 16 frames held the odometry back there (the hand-held walk keyframes every 0.2 m:
// 4.1 -> 5.4 ms a frame, 1.27 ms of it waiting), though loop closure's own time is less than the
// odometry's over the run; only the backlog at the end is waited for now (0.2 ms a frame there).
constexpr std::size_t kLoopQueuePoints = 2'000'000;

// The exported map: one point per cell of `voxel` metres, first come first kept, optionally only
// near the sensor. Bounded by the area the run covered, not by the number of frames.
class PointMap {
 public:
  explicit PointMap(double voxel) : voxel_(voxel) {}
  void add(const PointCloud& cloud, const Pose& pose) {
    for (const Point& p : cloud.points) {
      const Eigen::Vector3d w = pose * p.cast<double>();
      if (cells_.find_or_insert(voxel_key(w, voxel_)).inserted) points_.push_back(w.cast<float>());
    }
  }
  void keep_within(const Eigen::Vector3d& center, double radius) {
    const double r2 = radius * radius;
    std::vector<Point> kept;
    cells_.clear();
    for (const Point& p : points_) {
      if ((p.cast<double>() - center).squaredNorm() > r2) continue;
      cells_.find_or_insert(voxel_key(p.cast<double>(), voxel_));
      kept.push_back(p);
    }
    points_.swap(kept);
  }
  PointCloud cloud() const {
    PointCloud c;
    c.points = points_;
    return c;
  }

 private:
  double voxel_;
  VoxelSet cells_;
  std::vector<Point> points_;
};

nlohmann::ordered_json stages_json(const std::vector<StageStatistics>& stages) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const StageStatistics& s : stages)
    j[s.name] = {{"mean_ms", s.mean_ms}, {"max_ms", s.max_ms}};
  return j;
}

// How far the run can be trusted, from its frames' health records (frame_stats.hpp).
nlohmann::ordered_json health_json(const std::vector<FrameStats>& frames) {
  std::size_t uncertain = 0, recovered = 0, global_starts = 0, thin = 0, disagreeing = 0;
  std::vector<double> paired;
  for (const FrameStats& f : frames) {
    uncertain += f.prior_uncertain;
    recovered += f.recovered;
    global_starts += f.global_start;
    disagreeing += health::stages_disagree(f);
    thin += health::thin_map(f);
    if (f.fine_paired_fraction > 0.0) paired.push_back(f.fine_paired_fraction);
  }
  std::sort(paired.begin(), paired.end());
  return {
      {"uncertain_priors", uncertain},
      {"recoveries", recovered},
      {"global_starts", global_starts},
      {"thin_map_frames", thin},
      {"coarse_fine_disagreements", disagreeing},
      {"median_fine_paired_fraction", paired.empty() ? 0.0 : paired[paired.size() / 2]},
      // The beam elevation correction the run ended with (elevation_estimate's decision).
      {"elevation_correction_deg", frames.empty() ? 0.0 : frames.back().elevation_correction_deg}};
}

// The keys of `scanmatch eval --json`.
// The ground truth of the frames run, and the estimate's ATE against it.
void evaluate(const std::optional<Trajectory>& truth, RunSummary& summary) {
  if (!truth || summary.frames == 0) return;
  const auto n = static_cast<std::ptrdiff_t>(std::min(summary.frames, truth->size()));
  summary.ground_truth.assign(truth->poses.begin(), truth->poses.begin() + n);
  summary.ate = compute_ate(summary.ground_truth,
                            std::vector<Pose>(summary.poses.begin(), summary.poses.begin() + n));
}

void write_ground_truth(const std::string& dir, const std::optional<Trajectory>& truth,
                        const RunSummary& summary) {
  if (summary.ground_truth.empty()) return;
  Trajectory gt;
  gt.poses = summary.ground_truth;
  if (truth->has_timestamps())
    gt.timestamps.assign(truth->timestamps.begin(),
                         truth->timestamps.begin() + static_cast<std::ptrdiff_t>(gt.size()));
  write_trajectory(dir + "/poses_gt.txt", gt, TrajectoryFormat::kKitti);
  if (gt.has_timestamps()) write_trajectory(dir + "/poses_gt_tum.txt", gt, TrajectoryFormat::kTum);
}

// The registered frames gathered per loop-closure keyframe (in the keyframe's frame, downsampled
// to the exported map's voxel), so that the map can be rebuilt from the optimized keyframe poses.
// Memory grows with the keyframes, each holding about one view at the map's voxel.
class KeyframeClouds {
 public:
  explicit KeyframeClouds(double voxel) : voxel_(voxel) {}
  void add(std::size_t keyframe, const PointCloud& frame, const Pose& keyframe_from_frame) {
    if (keyframe >= clouds_.size()) {
      settle();
      clouds_.resize(keyframe + 1);
    }
    PointCloud& cloud = clouds_[keyframe];
    const Eigen::Isometry3f T = keyframe_from_frame.cast<float>();
    for (const Point& p : frame.points) cloud.points.push_back(T * p);
    if (cloud.size() > 4 * kSettleEvery) settle();
  }
  /// The map of every keyframe's cloud placed at `keyframe_pose(k)`.
  template <class PoseOf>
  void add_to(PointMap& map, PoseOf keyframe_pose) {
    settle();
    for (std::size_t k = 0; k < clouds_.size(); ++k) map.add(clouds_[k], keyframe_pose(k));
  }

 private:
  static constexpr std::size_t kSettleEvery = 50000;
  void settle() {
    if (clouds_.empty()) return;
    try {
      clouds_.back() = voxel_downsample(clouds_.back(), voxel_);
    } catch (const Error&) {
      // a coordinate beyond the voxel index range: keep the points undownsampled
    }
  }
  double voxel_;
  std::vector<PointCloud> clouds_;
};

// The accepted loops, each relative pose between the two frames' reported poses (as poses.txt
// gives them, the frame start): loop closure measured it between their registration poses.
nlohmann::ordered_json loops_json(const std::vector<Loop3D>& loops,
                                  const std::vector<Pose>& reported_from_registered) {
  nlohmann::ordered_json j = nlohmann::ordered_json::array();
  for (const Loop3D& l : loops) {
    if (l.outlier) continue;
    const Pose relative = orthonormalized(reported_from_registered.at(l.from_frame).inverse() *
                                          l.relative * reported_from_registered.at(l.to_frame));
    const Eigen::Matrix<double, 6, 1> xyz_rpy = to_xyz_rpy(relative);
    const std::array<double, 12> row = to_kitti_row(relative);
    j.push_back({{"from", l.from_frame},
                 {"to", l.to_frame},
                 {"from_keyframe", l.from_keyframe},
                 {"to_keyframe", l.to_keyframe},
                 {"x", xyz_rpy(0)},
                 {"y", xyz_rpy(1)},
                 {"z", xyz_rpy(2)},
                 {"roll", xyz_rpy(3)},
                 {"pitch", xyz_rpy(4)},
                 {"yaw", xyz_rpy(5)},
                 {"kitti_row", row},
                 {"overlap", l.overlap},
                 {"error_m", l.error}});
  }
  return j;
}

}  // namespace

const StageStatistics& RunSummary::stage(std::string_view name) const {
  for (const StageStatistics& s : stages)
    if (s.name == name) return s;
  throw std::out_of_range("no odometry stage '" + std::string(name) + "'");
}

RunSummary run_odometry(SequenceSource& source, const OdometryConfig& config,
                        const RunOptions& options) {
  const std::unique_ptr<FrameOdometry> odometry = make_frame_odometry(config);
  const std::optional<Trajectory> truth = source.ground_truth();
  RunSummary summary;
  summary.method = config.method;
  summary.source = source.describe();
  const bool write = !options.out_dir.empty();
  const std::string dir = options.out_dir;
  if (options.write_map && options.map_format != "pcd" && options.map_format != "ply")
    throw Error("map format must be pcd or ply (got '" + options.map_format + "')");
  if (!(options.map_voxel_size > 0.0)) throw Error("map export voxel size must be positive");
  std::unique_ptr<TrajectoryWriter> kitti, tum;
  std::unique_ptr<TimingWriter<FrameStats>> timing;
  if (write) {
    create_run_folder(dir);
    write_file_atomic(dir + "/config.json", odometry_run_config_to_json({config, options}));
    kitti = std::make_unique<TrajectoryWriter>(dir + "/poses.txt", TrajectoryFormat::kKitti);
    tum = std::make_unique<TrajectoryWriter>(dir + "/poses_tum.txt", TrajectoryFormat::kTum);
    timing = std::make_unique<TimingWriter<FrameStats>>(dir + "/timing.csv");
  }
  const std::size_t total =
      options.max_frames > 0 ? std::min(options.max_frames, source.size()) : source.size();
  PointMap map(options.map_voxel_size);
  KeyframeClouds keyframe_clouds(options.map_voxel_size);
  struct LoopInput {
    PointCloud points;  ///< the registered frame's positions (loop closure uses no other field)
    Pose registered = Pose::Identity();
    bool to_map = false;  ///< the points also go into keyframe_clouds
  };
  // Fed in frame order; it owns the loop closure and `keyframe_clouds` until finish().
  std::optional<LoopClosureRun<LoopClosure3D, LoopInput>> closure;
  if (options.loop_closure)
    closure.emplace(
        options.loop, options.loop_closure_thread, kLoopQueuePoints,
        [&](LoopClosure3D& loops, LoopInput& in) {
          loops.add_frame(in.points, in.registered);
          if (in.to_map) {
            const std::size_t index = loops.frames() - 1;
            keyframe_clouds.add(loops.keyframe_of(index), in.points,
                                loops.offset_in_keyframe(index));
          }
        },
        [](const LoopInput& in) { return in.points.size() + 1; });
  // Per frame, its reported pose in the frame of the pose its points were registered at (the
  // pipeline reports the frame start, registers at mid-frame): the loop-closed reported pose is
  // the loop-closed registration pose followed by it.
  std::vector<Pose> reported_from_registered;
  // A registered frame goes to the map and loop closure once the odometry's world frame is settled
  // (world_settles_after): until then its points wait here, in the registration frame.
  struct Unsettled {
    std::optional<PointCloud> points;  ///< none: a bridged frame or a method that keeps none
    Pose registration_from_frame = Pose::Identity();
    std::size_t index = 0;
  };
  std::vector<Unsettled> unsettled;
  const auto hand_out = [&](const PointCloud* points, const Pose& registration_from_frame,
                            const Pose& reported, std::size_t index) {
    const Pose world_from_frame = odometry->world_from_registration() * registration_from_frame;
    if (points != nullptr && options.write_map) {
      map.add(*points, world_from_frame);
      if (options.map_export_radius > 0.0 && index % 50 == 0)
        map.keep_within(reported.translation(), options.map_export_radius);
    }
    if (closure) {
      // A bridged frame (or a method that keeps no points) adds its pose only.
      LoopInput in;
      in.registered = points != nullptr ? world_from_frame : reported;
      // A copy: *points is the odometry's and changes with the next frame.
      if (points != nullptr) in.points.points = points->points;
      in.to_map = points != nullptr && options.write_map;
      reported_from_registered.push_back(in.registered.inverse() * reported);
      closure->push(std::move(in));
    }
  };
  const auto hand_out_unsettled = [&] {
    for (Unsettled& u : unsettled) {
      // Frame 0 was deskewed once the first motion was known: hand out that one.
      const PointCloud* settled = u.index == 0 ? odometry->settled_first_frame() : nullptr;
      if (settled != nullptr && u.points) {
        u.points = *settled;
        u.registration_from_frame = Pose::Identity();
      }
      hand_out(u.points ? &*u.points : nullptr, u.registration_from_frame, summary.poses[u.index],
               u.index);
    }
    unsettled.clear();
  };
  // The frames before the world settles were returned in a provisional world: once it settles
  // (or the run ends first) they take their settled poses, and only then are they written.
  bool poses_settled = false;
  std::size_t written_poses = 0;
  const auto settle_poses = [&] {
    if (poses_settled) return;
    settle_early_poses(*odometry, summary.poses);
    poses_settled = true;
  };
  const auto write_poses_until = [&](std::size_t end) {
    for (; written_poses < end; ++written_poses) {
      kitti->write(summary.poses[written_poses], summary.timestamps[written_poses]);
      tum->write(summary.poses[written_poses], summary.timestamps[written_poses]);
    }
  };
  ProgressReporter progress("odometry " + config.method, total, "frames", options.quiet);
  Frame frame;
  double pipeline_ms = 0.0;
  const SpinTiming spin_timing{config.spin_period, config.spin_start_azimuth,
                               config.spin_clockwise};
  const Stopwatch run_time;
  while (summary.frames < total) {
    if (options.stop && options.stop->load()) {
      summary.interrupted = true;
      break;
    }
    try {
      if (!source.next(frame)) break;
    } catch (const Error& e) {
      summary.error = e.what();  // the run ends here, keeping what it finished
      break;
    }
    if (config.spin_times && !frame.cloud.has_time())
      assign_azimuth_times(frame.cloud, spin_timing);
    const Pose pose = odometry->register_frame(frame.cloud, frame.timestamp);
    const FrameStats& s = odometry->last_stats();
    pipeline_ms += s.total_ms;
    if (s.bridged && summary.frames > 0) {
      ++summary.bridged_frames;
      if (!options.quiet)
        std::fprintf(stderr, "odometry: frame %zu (%s): %s, bridged by the motion prior\n",
                     summary.frames, frame.name.c_str(),
                     s.points_downsampled < 20 ? "too few valid points" : "registration failed");
    }
    summary.poses.push_back(pose);
    summary.timestamps.push_back(frame.timestamp);
    summary.stats.push_back(s);
    const bool settled = summary.frames + 1 >= odometry->world_settles_after();
    if (settled) settle_poses();
    if (write) {
      if (settled) write_poses_until(summary.frames + 1);
      timing->write(summary.frames, frame.timestamp, s);
    }
    // A bridged frame has no registered points of its own (an empty frame leaves the previous
    // one in last_frame()); it would only add a copy or a guess to the map.
    Pose registration_from_frame = Pose::Identity();
    const PointCloud* map_frame = (options.write_map || closure) && !s.bridged
                                      ? odometry->last_map_frame(registration_from_frame)
                                      : nullptr;
    if (options.write_map || closure) {
      if (summary.frames + 1 < odometry->world_settles_after()) {
        Unsettled u{std::nullopt, registration_from_frame, summary.frames};
        if (map_frame != nullptr) u.points = *map_frame;
        unsettled.push_back(std::move(u));
      } else {
        hand_out_unsettled();
        hand_out(map_frame, registration_from_frame, pose, summary.frames);
      }
    }
    ++summary.frames;
    progress.update(summary.frames);
  }
  progress.finish();
  settle_poses();  // a run shorter than the settling
  if (write) write_poses_until(summary.poses.size());
  hand_out_unsettled();
  if (closure) closure->finish();  // also after an interruption: the queued frames are worked
  if (summary.frames > 0)
    summary.wall_ms_per_frame = run_time.ms() / static_cast<double>(summary.frames);
  summary.stages = stage_statistics(summary.stats);
  summary.frames_per_second = pipeline_ms > 0.0 ? 1000.0 * summary.frames / pipeline_ms : 0.0;
  evaluate(truth, summary);
  if (closure) {
    const LoopClosure3D& loops = closure->loop_closure();
    summary.loop_closure = closure->record(summary.frames);
    for (std::size_t i = 0; i < loops.frames(); ++i)
      summary.optimized_poses.push_back(
          orthonormalized(loops.pose(i) * reported_from_registered[i]));
    if (!summary.ground_truth.empty())
      summary.ate_optimized = compute_ate(
          summary.ground_truth,
          std::vector<Pose>(summary.optimized_poses.begin(),
                            summary.optimized_poses.begin() +
                                static_cast<std::ptrdiff_t>(summary.ground_truth.size())));
  }

  if (write) {
    if (options.write_map) {
      if (options.map_export_radius > 0.0 && !summary.poses.empty())
        map.keep_within(summary.poses.back().translation(), options.map_export_radius);
      // map.* is the best map there is: the loop-closed one with loop closure.
      write_cloud(dir + (closure ? "/map_odometry." : "/map.") + options.map_format, map.cloud());
      if (closure) {
        PointMap optimized_map(options.map_voxel_size);
        keyframe_clouds.add_to(
            optimized_map, [&](std::size_t k) { return closure->loop_closure().graph().pose(k); });
        if (options.map_export_radius > 0.0 && !summary.optimized_poses.empty())
          optimized_map.keep_within(summary.optimized_poses.back().translation(),
                                    options.map_export_radius);
        write_cloud(dir + "/map." + options.map_format, optimized_map.cloud());
      }
    }
    if (closure) {
      Trajectory optimized;
      optimized.poses = summary.optimized_poses;
      optimized.timestamps = summary.timestamps;
      write_trajectory(dir + "/poses_optimized.txt", optimized, TrajectoryFormat::kKitti);
      write_trajectory(dir + "/poses_optimized_tum.txt", optimized, TrajectoryFormat::kTum);
      write_json_atomic(dir + "/loops.json",
                        loops_json(closure->loop_closure().loops(), reported_from_registered));
    }
    write_ground_truth(dir, truth, summary);
    nlohmann::ordered_json j = {{"kind", kOdometryRunKind},
                                {"method", summary.method},
                                {"source", summary.source},
                                {"frames", summary.frames},
                                {"bridged_frames", summary.bridged_frames},
                                {"interrupted", summary.interrupted},
                                {"error", summary.error},
                                {"frames_per_second", summary.frames_per_second},
                                {"wall_ms_per_frame", summary.wall_ms_per_frame},
                                {"threads", config.threads},
                                {"stages", stages_json(summary.stages)},
                                {"health", health_json(summary.stats)}};
    if (summary.ate) {
      j["ate"] = ate_json(summary.ate_optimized ? *summary.ate_optimized : *summary.ate);
      if (closure) j["ate_odometry"] = ate_json(*summary.ate);
    }
    if (summary.loop_closure) j["loop_closure"] = loop_closure_json(*summary.loop_closure, "frame");
    j["options"] = nlohmann::ordered_json::parse(odometry_config_to_json(config));
    write_json_atomic(dir + "/summary.json", j);
  }
  if (!summary.error.empty()) throw Error(summary.error);
  return summary;
}

}  // namespace scanmatch
