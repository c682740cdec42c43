#include "scanmatch/odometry/odometry_pipeline.hpp"

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"

namespace scanmatch {

OdometryPipeline::OdometryPipeline(const OdometryConfig& config, bool keep_attributes,
                                   bool map_points)
    : config_(config),
      preprocessor_(preprocess_options(config, keep_attributes)),
      motion_(config),
      wants_map_points_(map_points) {
  check_odometry_config(config);
  config_.registration.solver.num_threads = config.threads;
}

Pose OdometryPipeline::register_frame(const PointCloud& frame, double timestamp) {
  const Stopwatch total;
  stats_ = FrameStats{};
  stats_.points_in = frame.size();
  if (frames_ == 0) timed_frames_ = frame.has_time();
  const MotionPrior& prior = motion_.predict(timestamp, frames_);
  // Deskew once a velocity is measured, and only above the dead band: deskewing by a velocity that
  // is itself estimation noise feeds that noise back into the next pose.
  const bool deskew = config_.deskew && frames_ > 1 && motion_.moving(motion_.velocity());
  const FrameMotion frame_motion{prior.motion, motion_.frame_period()};
  PointCloud down = preprocessor_.process(frame, deskew ? &frame_motion : nullptr,
                                          wants_map_points_ ? &map_points_ : nullptr);
  stats_.points_downsampled = down.size();
  stats_.preprocess_ms = total.ms();

  const Pose predicted = pose_ * prior.motion;
  Pose estimate = predicted;
  if (frames_ > 0) {
    try {
      estimate = this->estimate(down, prior, predicted, stats_);
    } catch (const Error&) {
      stats_.bridged = true;  // too few points or correspondences: keep the motion prior
      estimate = predicted;
    }
  }
  // Never let a failed solve poison the trajectory: a result far from the motion prior (or not
  // finite) is replaced by the prior.
  if (!motion_.within_gate(predicted, estimate)) {
    stats_.bridged = true;
    estimate = predicted;
  }
  estimate = orthonormalized(estimate);
  stats_.prior_uncertain = prior.uncertain;
  const Pose miss = predicted.inverse() * estimate;
  stats_.prior_miss_m = miss.translation().norm();
  stats_.prior_miss_deg = rotation_angle(miss) * kDegreesPerRadian;
  // A bridged frame keeps the last good velocity rather than one derived from the prior itself.
  if (frames_ > 0) motion_.record(orthonormalized(pose_.inverse() * estimate), stats_.bridged);
  pose_ = estimate;

  // The registration estimated the pose at mid-frame; the frame-start pose lies half the frame
  // motion before it. Keeping the mid-frame pose as the state matters: deskewing to the frame
  // start would shift a frame by half of any velocity error, and that error would feed back into
  // the next velocity.
  Pose reported = pose_;
  if (timed_frames_ && frames_ > 0) {
    const Pose& velocity = motion_.velocity();
    reported = pose_ * se3_exp(-0.5 * se3_log(velocity));
    // The world is frame 0's start pose, which is known once the first motion is: half of it
    // before frame 0's mid-frame pose (the internal origin). A first motion within a few times
    // the deskew dead band is mostly the first registration's noise (a still start): anchoring by
    // it would offset every later pose.
    if (frames_ == 1 && motion_.moving(velocity, 3.0))
      world_from_internal_ = se3_exp(0.5 * se3_log(velocity));
    reported = world_from_internal_ * reported;
  }
  update_reference(std::move(down), map_points_, pose_, stats_.bridged, stats_);
  ++frames_;
  stats_.total_ms = total.ms();
  return orthonormalized(reported);
}

const PointCloud* OdometryPipeline::last_map_frame(Pose& world_from_frame) const {
  world_from_frame = world_from_internal_ * pose_;
  return &last_frame();
}

}  // namespace scanmatch
