#include "scanmatch/odometry/odometry.hpp"

#include <algorithm>
#include <chrono>

#include "scanmatch/core/error.hpp"
#include "scanmatch/geometry/voxel_filter.hpp"
#include "scanmatch/registration/factors.hpp"

namespace scanmatch {
namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

GaussianVoxelMapOptions map_options(const OdometryConfig& c) {
  GaussianVoxelMapOptions o;
  o.voxel_size = c.map_voxel_size;
  o.merge_threshold = c.merge_threshold;
  o.planar_epsilon = c.registration.ctf_epsilon;
  return o;
}
}  // namespace

Odometry::Odometry(const OdometryConfig& config) : config_(config), map_(map_options(config)) {
  if (config.method != "ctf-icp") {
    const auto names = registration_method_names();
    if (std::find(names.begin(), names.end(), config.method) == names.end())
      throw Error("unknown odometry method '" + config.method +
                  "' (ctf-icp or a registration method)");
  }
  config_.registration.solver.num_threads = config.threads;
}

Pose Odometry::register_frame(const PointCloud& frame, double timestamp) {
  const auto start = Clock::now();
  stats_ = FrameStats{};
  stats_.points_in = frame.size();
  if (frames_ > 0 && timestamp > last_timestamp_) frame_period_ = timestamp - last_timestamp_;
  last_timestamp_ = timestamp;
  PointCloud down;
  if (config_.deskew && frame.has_time() && frames_ > 1) {
    // Each point was measured at its own time offset: move it into the frame-start sensor frame
    // by the fraction of the (constant-velocity) frame motion that had happened by then.
    const Vector6d xi = se3_log(velocity_);
    PointCloud deskewed = frame;
    for (std::size_t i = 0; i < frame.size(); ++i)
      deskewed.points[i] =
          (se3_exp(xi * (frame.time[i] / frame_period_)) * frame.points[i].cast<double>())
              .cast<float>();
    down = voxel_downsample(deskewed, config_.voxel_size);
  } else {
    down = voxel_downsample(frame, config_.voxel_size);
  }
  stats_.points_downsampled = down.size();
  stats_.preprocess_ms = ms_since(start);

  const Pose predicted = pose_ * velocity_;
  Pose estimate = predicted;
  const bool ctf = config_.method == "ctf-icp";
  if (frames_ > 0 && down.size() >= 20 && previous_.size() >= 20) {
    try {
      // Coarse (ctf-icp: NDT) or the baseline's own frame-to-frame registration from the prior.
      const auto coarse_start = Clock::now();
      RegistrationOptions o = config_.registration;
      o.method = ctf ? "ndt" : config_.method;
      if (ctf) o.voxel_resolution = config_.ndt_resolution;
      const RegistrationResult coarse = register_clouds(down, previous_, o, velocity_);
      estimate = pose_ * coarse.transform;
      stats_.coarse_ms = ms_since(coarse_start);
      stats_.iterations = coarse.iterations;
      stats_.condition_number = coarse.condition_number;
      if (ctf && config_.fine_stage && map_.size() > 0) {
        const auto fine_start = Clock::now();
        // Levenberg-Marquardt: with the stiff (1, 1, 1e-6) information and one voxel per point the
        // cost jumps where points change voxels; only cost-decreasing steps are taken.
        SolverOptions fine_solver = config_.registration.solver;
        fine_solver.levenberg_marquardt = true;
        const RegistrationResult fine =
            optimize(CtfFineFactor{down, map_, 1}, estimate, fine_solver);
        if (fine.inliers >= 20) estimate = fine.transform;
        stats_.fine_ms = ms_since(fine_start);
        stats_.iterations += fine.iterations;
        stats_.condition_number = fine.condition_number;
      }
    } catch (const Error&) {
      stats_.bridged = true;  // too few points or correspondences: keep the motion prior
      estimate = predicted;
    }
  } else if (frames_ > 0) {
    stats_.bridged = true;
  }
  // Never let a failed solve poison the trajectory: a result far from the motion prior (or not
  // finite) is replaced by the prior.
  const Pose jump = predicted.inverse() * estimate;
  if (!to_matrix(estimate).allFinite() || jump.translation().norm() > config_.max_jump ||
      rotation_angle(jump) > config_.max_jump_angle) {
    stats_.bridged = true;
    estimate = predicted;
  }

  if (ctf && (config_.map_update || frames_ == 0)) {
    const auto map_start = Clock::now();
    map_.insert(down, estimate);
    if (frames_ == 0) map_.flush();  // the first frame builds the map at once
    map_.remove_far(estimate.translation(), config_.map_radius);
    stats_.map_ms = ms_since(map_start);
  }
  // A bridged frame keeps the last good velocity rather than one derived from the prior itself.
  estimate = orthonormalized(estimate);
  if (!stats_.bridged)
    velocity_ = frames_ > 0 ? orthonormalized(pose_.inverse() * estimate) : Pose::Identity();
  pose_ = estimate;
  previous_ = std::move(down);
  ++frames_;
  stats_.total_ms = ms_since(start);
  return pose_;
}

}  // namespace scanmatch
