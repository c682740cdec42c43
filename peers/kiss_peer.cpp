// KISS-ICP (Vizzo et al., 2023) as an odometry peer (`--method kiss-icp`), built with
// -DSCANMATCH_WITH_KISS=ON against an installed KISS-ICP C++ core (docs/benchmarks.md, Peers). Its
// own pipeline and defaults, except the ranges and threads, which come from the run's
// configuration, and the voxel size, max_range / 100 as KISS-ICP's own configuration derives it.
// Written against the pipeline API with KissICP::pose(), delta() and RegisterFrame(points, times)
// (KISS-ICP 1.x; older releases expose poses() instead).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include <kiss_icp/pipeline/KissICP.hpp>

#include "scanmatch/odometry/frame_odometry.hpp"

namespace scanmatch {
namespace {

using Clock = std::chrono::steady_clock;

class KissOdometry final : public FrameOdometry {
 public:
  explicit KissOdometry(const OdometryConfig& config)
      : kiss_(kiss_config(config)), config_deskew_(config.deskew) {}

  Pose register_frame(const PointCloud& frame, double) override {
    const auto start = Clock::now();
    stats_ = FrameStats{};
    stats_.points_in = frame.size();
    // KISS-ICP rescales each frame's point times to [0, 1] itself and deskews to the scan's end;
    // a frame without times goes in without (KISS then takes it as instantaneous).
    std::vector<Eigen::Vector3d> points;
    std::vector<double> times;
    points.reserve(frame.size());
    const bool timed = frame.has_time() && config_deskew_;
    for (std::size_t i = 0; i < frame.size(); ++i) {
      if (!frame.points[i].allFinite() || (timed && !std::isfinite(frame.time[i]))) continue;
      points.push_back(frame.points[i].cast<double>());
      if (timed) times.push_back(frame.time[i]);
    }
    const auto [deskewed, keypoints] = kiss_.RegisterFrame(points, times);
    stats_.points_downsampled = keypoints.size();
    last_frame_.points.clear();
    for (const Eigen::Vector3d& p : deskewed) last_frame_.points.push_back(p.cast<float>());
    // Deskewed frames are placed at the scan's end; our poses (and ground truth) are the frame
    // start's, one frame-to-frame motion earlier.
    const Sophus::SE3d frame_start = timed ? kiss_.pose() * kiss_.delta().inverse() : kiss_.pose();
    last_pose_ = from_matrix(frame_start.matrix());
    stats_.total_ms = stats_.coarse_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    return last_pose_;
  }

  const FrameStats& last_stats() const override { return stats_; }
  const PointCloud* last_map_frame(Pose& world_from_frame) const override {
    world_from_frame = last_pose_;
    return &last_frame_;
  }

 private:
  static kiss_icp::pipeline::KISSConfig kiss_config(const OdometryConfig& config) {
    kiss_icp::pipeline::KISSConfig k;
    k.max_range = config.max_range;
    k.min_range = config.min_range;
    k.voxel_size = config.max_range / 100.0;
    k.max_num_threads = config.threads;
    k.deskew = config.deskew;
    return k;
  }

  kiss_icp::pipeline::KissICP kiss_;
  bool config_deskew_;
  FrameStats stats_;
  PointCloud last_frame_;
  Pose last_pose_ = Pose::Identity();
};

[[maybe_unused]] const bool kRegistered = register_odometry_peer(
    "kiss-icp", "KISS-ICP's C++ pipeline with its defaults (installed, not vendored)",
    [](const OdometryConfig& c) { return std::make_unique<KissOdometry>(c); });

}  // namespace
}  // namespace scanmatch
