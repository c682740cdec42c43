// KISS-ICP (Vizzo et al., 2023) as an odometry peer (`--method kiss-icp`), built with
// -DSCANMATCH_WITH_KISS=ON against an installed KISS-ICP C++ core (find_package(kiss_icp) or
// -DSCANMATCH_KISS_ROOT=PREFIX; docs/benchmarks.md, Peers). Its own pipeline (kiss_icp::pipeline::
// KissICP with RegisterFrame(points, times), pose() and delta()) and its defaults, except what the
// run's configuration says about the sensor: min and max range, whether to deskew, and the
// threads; the voxel size is max_range / 100, as KISS-ICP's own configuration derives it.
//
// Two things the adapter does so that the comparison is of the method, not of conventions:
// - Time: KISS-ICP deskews every point to the END of its sweep (normalised time 1), so its pose is
//   the sensor at the sweep's end; ours and the ground truth are at the frame's START. Under
//   KISS-ICP's own motion model (the sweep spans its last delta) the start pose is
//   pose() * delta()^-1, which is what this peer reports for timed frames.
// - Threads: KISS-ICP's constructors set a process-wide TBB limit (a static tbb::global_control
//   with max_allowed_parallelism = its thread count, kept until exit). The peer constructs it with
//   0 threads outside any arena, so that limit is the machine's default concurrency (TBB's own
//   default: nothing changes for the other methods), and runs each frame in a task_arena of
//   config.threads instead.

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <kiss_icp/pipeline/KissICP.hpp>
#include <memory>
#include <vector>

#include "scanmatch/core/error.hpp"
#include "scanmatch/odometry/frame_odometry.hpp"

namespace scanmatch {
namespace {

using Clock = std::chrono::steady_clock;

Pose to_pose(const Sophus::SE3d& T) {
  return from_matrix(T.matrix());
}

class KissOdometry final : public FrameOdometry {
 public:
  explicit KissOdometry(const OdometryConfig& config)
      : arena_(checked_threads(config.threads)), kiss_(construct(config)) {}

  Pose register_frame(const PointCloud& frame, double) override {
    const auto start = Clock::now();
    stats_ = FrameStats{};
    stats_.points_in = frame.size();
    // Point times as they are (KISS-ICP normalises them to [0, 1] itself); none when the frame has
    // no times or they span no time, which KISS-ICP takes as "do not deskew".
    std::vector<Eigen::Vector3d> points;
    std::vector<double> times;
    points.reserve(frame.size());
    bool timed = frame.has_time();
    double t_min = INFINITY, t_max = -INFINITY;
    for (std::size_t i = 0; i < frame.size(); ++i) {
      if (!frame.points[i].allFinite()) continue;
      if (timed && !std::isfinite(frame.time[i])) timed = false;
      points.push_back(frame.points[i].cast<double>());
      if (timed) {
        times.push_back(frame.time[i]);
        t_min = std::min(t_min, times.back());
        t_max = std::max(t_max, times.back());
      }
    }
    if (!timed || !(t_max > t_min)) times.clear();
    std::vector<Eigen::Vector3d> deskewed, keypoints;
    arena_.execute([&] { std::tie(deskewed, keypoints) = kiss_->RegisterFrame(points, times); });
    stats_.points_downsampled = keypoints.size();
    last_frame_.points.clear();
    last_frame_.points.reserve(deskewed.size());
    for (const Eigen::Vector3d& p : deskewed) last_frame_.points.push_back(p.cast<float>());
    // KISS-ICP's frame: the sweep's end for deskewed frames (see the top of the file).
    end_pose_ = to_pose(kiss_->pose());
    const bool deskewed_frame = kiss_config_.deskew && !times.empty();
    const Pose pose = deskewed_frame ? end_pose_ * to_pose(kiss_->delta()).inverse() : end_pose_;
    stats_.total_ms = stats_.fine_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    return pose;
  }

  const FrameStats& last_stats() const override { return stats_; }
  const PointCloud* last_map_frame(Pose& registration_from_frame) const override {
    registration_from_frame = end_pose_;  // the deskewed points, in the sweep-end frame
    return &last_frame_;
  }

 private:
  static int checked_threads(int threads) {
    if (threads < 1) throw Error("odometry: threads must be at least 1");
    return threads;
  }
  std::unique_ptr<kiss_icp::pipeline::KissICP> construct(const OdometryConfig& config) {
    kiss_config_.max_range = config.max_range;
    kiss_config_.min_range = config.min_range;
    kiss_config_.voxel_size = config.max_range / 100.0;
    kiss_config_.deskew = config.deskew;
    kiss_config_.max_num_threads = 0;  // see the top of the file
    std::unique_ptr<kiss_icp::pipeline::KissICP> kiss;
    tbb::task_arena(tbb::task_arena::automatic).execute([&] {
      kiss = std::make_unique<kiss_icp::pipeline::KissICP>(kiss_config_);
    });
    return kiss;
  }

  tbb::task_arena arena_;
  kiss_icp::pipeline::KISSConfig kiss_config_;
  std::unique_ptr<kiss_icp::pipeline::KissICP> kiss_;
  FrameStats stats_;
  PointCloud last_frame_;
  Pose end_pose_ = Pose::Identity();
};

[[maybe_unused]] const bool kRegistered = register_odometry_peer(
    "kiss-icp", "KISS-ICP's C++ pipeline with its defaults (installed, not vendored)",
    [](const OdometryConfig& c) { return std::make_unique<KissOdometry>(c); });

}  // namespace
}  // namespace scanmatch
