#include "scanmatch/odometry/odometry_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"

namespace scanmatch {
namespace {

/// Frames follow one another (the world anchor may be extrapolated across them) when the time
/// step is within this many of frame 0's sweeps.
constexpr double kContiguousSweeps = 1.5;

/// s: the sweep of frames without point times (most spinning and Livox sensors run at 10 Hz).
constexpr double kNominalSweep = 0.1;

/// rad/s: how fast a vehicle may turn between keyframes (a car at a corner: 90 deg in 3 s), for
/// the coarse stage's turned starts.
constexpr double kTurnRate = 0.5;

/// The early motions along the way lie on a line where its slope is this many standard errors.
constexpr double kLineSignificance = 5.0;

}  // namespace

OdometryPipeline::OdometryPipeline(const OdometryConfig& config, bool keep_attributes,
                                   bool map_points, bool deskews_again)
    : config_(config),
      preprocessor_(preprocess_options(config, keep_attributes)),
      motion_(config),
      wants_map_points_(map_points),
      deskews_again_(deskews_again),
      estimating_elevation_(config.elevation_estimate && config.elevation_correction_deg == 0.0) {
  check_odometry_config(config);
  // The one place the thread count reaches the solver: every stage is made from config().
  config_.registration.solver.num_threads = config.threads;
}

Pose OdometryPipeline::register_frame(const PointCloud& frame, double timestamp) {
  const Stopwatch total;
  stats_ = FrameStats{};
  stats_.points_in = frame.size();
  stats_.elevation_correction_deg =
      preprocessor_.options().elevation_correction * kDegreesPerRadian;
  if (frames_ == kWorldSettlesAfter) settled_first_frame_ = PointCloud{};  // handed out by now
  if (frames_ == 0) {
    timed_frames_ = frame.has_time();
    first_sweep_ = latest_point_time(frame);
  }
  motion_.predict(timestamp, frames_);
  if (frames_ > 1 && long_time_step()) motion_.set_turn_reach(turn_reach());
  const MotionPrior& prior = motion_.prior();
  // Deskew once a velocity is measured, and only above the dead band: deskewing by a velocity that
  // is itself estimation noise feeds that noise back into the next pose.
  const bool deskew = config_.deskew && frames_ > 1 && motion_.moving(motion_.velocity());
  const FrameMotion frame_motion = over_time_step(prior.motion);
  PointCloud down = preprocessor_.process(frame, deskew ? &frame_motion : nullptr,
                                          wants_map_points_ ? &map_points_ : nullptr);
  if (frames_ == 0 && deskews_again_) set_first_frame_detail(frame_detail(frame, nullptr));
  stats_.points_downsampled = down.size();
  stats_.preprocess_ms = total.ms();
  const Stopwatch waiting;
  finish_reference_update();
  stats_.map_ms = waiting.ms();  // the last frame's reference update, where this frame waited

  const bool redeskew = deskews_again_ && config_.deskew && timed_frames_ &&
                        (config_.redeskew_translation > 0.0 || config_.redeskew_rotation > 0.0);
  if (frames_ == 0 && redeskew) first_frame_ = frame;
  const Pose predicted = pose_ * prior.motion;
  Pose estimate = predicted;
  if (frames_ > 0) {
    try {
      estimate = this->estimate(down, prior, predicted, stats_);
      if (redeskew && !stats_.bridged)
        estimate = deskew_again(frame, prior, deskew, estimate, down);
    } catch (const Error&) {
      stats_.bridged = true;  // too few points or correspondences: keep the motion prior
      estimate = predicted;
    }
  }
  if (frames_ > 0) first_frame_ = PointCloud{};
  // Never let a failed solve poison the trajectory: a result far from the motion prior (or not
  // finite) is replaced by the prior.
  // A global start's result is verified by its own evidence (more of the frame overlapping the
  // first one), not by the first motion's prior, the identity, which says nothing.
  const bool verified = stats_.global_start && estimate.matrix().allFinite();
  if (!verified && !motion_.within_gate(predicted, estimate)) {
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
    reported = pose_ * se3_exp(-middle_share() * se3_log(velocity));
    if (frames_ == 1) first_velocity_ = se3_log(velocity);
  }
  if (frames_ < kWorldSettlesAfter) {
    early_starts_[frames_] = reported;
    if (timed_frames_ && frames_ > 0) {
      early_middles_[frames_] = pose_;
      early_velocities_[frames_] = se3_log(motion_.velocity());
      early_middle_shares_[frames_] = middle_share();
      if (early_fitted_ + 1 == frames_ && deskews_again_ && !stats_.bridged &&
          motion_.frame_period() <= kContiguousSweeps * first_sweep_)
        early_fitted_ = frames_;
      settle_early_frames();
      reported = early_starts_[frames_];
    }
  }
  reported = world_from_internal_ * reported;
  if (estimating_elevation_) offer_elevation_pair(down);
  update_reference(std::move(down), map_points_, pose_, stats_.bridged, stats_);
  ++frames_;
  stats_.total_ms = total.ms();
  return orthonormalized(reported);
}

Pose OdometryPipeline::deskew_again(const PointCloud& frame, const MotionPrior& prior,
                                    bool deskewed, const Pose& estimate, PointCloud& down) {
  const Pose measured = orthonormalized(pose_.inverse() * estimate);
  const bool first_motion = frames_ == 1 && !first_frame_.empty();
  if (!motion_.moving(measured)) return estimate;
  const Pose miss = (deskewed ? prior.motion : Pose::Identity()).inverse() * measured;
  const bool missed = miss.translation().norm() > config_.redeskew_translation ||
                      rotation_angle(miss) > config_.redeskew_rotation;
  if (!first_motion && !missed) return estimate;
  const Stopwatch preprocess_time;
  const FrameMotion frame_motion = over_time_step(measured);
  if (first_motion) {
    PointCloud first_map_points;
    PointCloud first = preprocessor_.process(first_frame_, &frame_motion,
                                             wants_map_points_ ? &first_map_points : nullptr);
    if (first.empty()) return estimate;
    set_first_frame_detail(frame_detail(first_frame_, &frame_motion));
    settled_first_frame_ = first;
    restart_reference(std::move(first), first_map_points);
  }
  PointCloud again_map_points;
  PointCloud again =
      preprocessor_.process(frame, &frame_motion, wants_map_points_ ? &again_map_points : nullptr);
  const double preprocess_ms = preprocess_time.ms();
  MotionPrior settled = prior;
  settled.motion = measured;
  settled.uncertain = false;
  FrameStats second = stats_;
  Pose result;
  try {
    result = this->estimate(again, settled, estimate, second);
  } catch (const Error&) {
    return estimate;
  }
  if (second.bridged) return estimate;  // e.g. the frame lost too many points: keep the first
  second.coarse_ms += stats_.coarse_ms;
  second.fine_ms += stats_.fine_ms;
  second.iterations += stats_.iterations;
  second.recovered = second.recovered || stats_.recovered;
  second.preprocess_ms += preprocess_ms;
  second.redeskewed = true;
  second.points_downsampled = again.size();
  stats_ = second;
  down = std::move(again);
  map_points_ = std::move(again_map_points);
  return result;
}

void OdometryPipeline::offer_elevation_pair(const PointCloud& frame) {
  const Stopwatch time;
  // The correction this frame was preprocessed with: a pair of frames corrected alike measures
  // the bias left over.
  const double corrected = stats_.elevation_correction_deg / kDegreesPerRadian;
  if (stats_.bridged) {
    elevation_previous_ = PointCloud{};  // no trusted relative pose to the next frame
    return;
  }
  const Pose step = elevation_previous_pose_.inverse() * pose_;
  if (elevation_previous_correction_ != corrected) {
    // The previous frame was preprocessed before the correction changed: correct it alike.
    const ElevationTurn change(elevation_previous_correction_ - corrected);
    for (Point& p : elevation_previous_.points) p = change(p);
    elevation_previous_correction_ = corrected;
  }
  const bool paired = !elevation_previous_.empty();
  if (paired && step.translation().norm() >= ElevationEstimate::kMinStep) {
    ElevationBiasFromPair pair = estimate_elevation_bias(elevation_previous_, frame, step);
    pair.bias += corrected;
    elevation_.add(pair);
    preprocessor_.set_elevation_correction(elevation_.correction());
    if (elevation_.decided()) {
      estimating_elevation_ = false;
      elevation_previous_ = PointCloud{};
      stats_.preprocess_ms += time.ms();
      return;
    }
  }
  // A pair needs a step: the previous frame stays until the sensor has moved far enough.
  if (!paired || step.translation().norm() >= ElevationEstimate::kMinStep) {
    elevation_previous_ = frame;
    elevation_previous_pose_ = pose_;
    elevation_previous_correction_ = corrected;
  }
  stats_.preprocess_ms += time.ms();
}

PointCloud OdometryPipeline::frame_detail(const PointCloud& frame,
                                          const FrameMotion* motion) const {
  return preprocessor_.map_detail(frame, motion);
}

void OdometryPipeline::settle_early_frames() {
  // The world is frame 0's start pose: half of frame 0's first-half motion before its mid-frame
  // pose (the internal origin; a share of it for keyframes, middle_share()). A frame reported as it
  // comes starts half of its mid-to-mid motion (the rate at its start) before its middle; the early
  // frames are reported again once the world settles, from what the frames after them measured:
  // - frame 0's rate is v1 and v2's line taken back to a quarter into it (a hand-held turn slows
  //   from 25 to 16.5 deg per frame), where the motion changed by more than the dead band;
  // - along the way, where the motions v1..vk lie on a line (kLineSignificance: a vehicle speeding
  //   up, not a hand-held sensor's bounce or a car's sway), frame 0's rate and every early frame's
  //   first-half rate come from that line. Speeding up by a per frame^2, a frame's start lies a/8
  //   behind where its mid-to-mid motion puts it: urban-hdl64 starts at 8 m/s^2 and frame 1 came
  //   out 10 mm ahead of frame 0; the line also passes the first registration's error on 1.15 times
  //   where two motions passed it 1.5 times.
  // Only where frames follow one another (kContiguousSweeps: across keyframes 0.5 s apart a car
  // speeding up is no constant acceleration, campus-os1 every 5th frame 0.29 -> 1.85 %), for a
  // registration trusted to deskew again (gicp 0.255 -> 0.290 %). Only the parts of the motion
  // above anchor_min_* anchor the world at all (a still start's noise or a robot's jitter would
  // turn every later pose).
  const std::size_t k = early_fitted_;
  Vector6d first_rate = first_velocity_;
  std::array<Vector6d, kWorldSettlesAfter> rates = early_velocities_;
  const Vector6d& v1 = early_velocities_[1];
  const Vector6d& v2 = early_velocities_[2];
  if (k >= 2 && motion_.moving(se3_exp(v1).inverse() * se3_exp(v2)))
    first_rate = 1.75 * v1 - 0.75 * v2;
  if (k >= 3) {
    // Along the way: a straight line through the motions v1..vk, least squares.
    Eigen::Vector3d way = Eigen::Vector3d::Zero();
    for (std::size_t i = 1; i <= k; ++i) way += early_velocities_[i].tail<3>();
    if (way.norm() > 0.0) way.normalize();
    const double middle = 0.5 * static_cast<double>(k + 1);
    double mean = 0.0, slope = 0.0, spread = 0.0;
    for (std::size_t i = 1; i <= k; ++i) {
      const double t = static_cast<double>(i) - middle,
                   along = way.dot(early_velocities_[i].tail<3>());
      mean += along / static_cast<double>(k);
      slope += t * along;
      spread += t * t;
    }
    slope /= spread;
    double residuals = 0.0;
    for (std::size_t i = 1; i <= k; ++i) {
      const double t = static_cast<double>(i) - middle;
      residuals += std::pow(way.dot(early_velocities_[i].tail<3>()) - mean - t * slope, 2);
    }
    const double deviation = std::sqrt(residuals / static_cast<double>(k - 2));
    const bool on_a_line = std::abs(slope) * std::sqrt(spread) >= kLineSignificance * deviation;
    if (on_a_line &&
        std::abs(slope) * static_cast<double>(k - 1) >= config_.deskew_min_translation) {
      const double along_start = mean + (0.25 - middle) * slope;  // a quarter into frame 0
      first_rate.tail<3>() += (along_start - way.dot(first_rate.tail<3>())) * way;
      for (std::size_t i = 1; i <= k; ++i) rates[i].tail<3>() += 0.25 * slope * way;
    }
  }
  world_from_internal_ = se3_exp(early_middle_shares_[1] * anchored_part(first_rate));
  for (std::size_t i = 1; i <= frames_; ++i)
    early_starts_[i] = early_middles_[i] * se3_exp(-early_middle_shares_[i] * rates[i]);
}

bool OdometryPipeline::long_time_step() const {
  const double sweep = first_sweep_ > 0.0 ? first_sweep_ : kNominalSweep;
  return motion_.frame_period() > kContiguousSweeps * sweep;
}

double OdometryPipeline::turn_reach() const {
  return std::max(2.0 * config_.rotation_starts * config_.rotation_start_step,
                  kTurnRate * motion_.frame_period());
}

double OdometryPipeline::middle_share() const {
  const double step = motion_.frame_period();
  if (step <= kContiguousSweeps * first_sweep_ || step <= 0.0) return 0.5;
  return 0.5 * first_sweep_ / step;
}

FrameMotion OdometryPipeline::over_time_step(const Pose& motion) const {
  const double step = motion_.frame_period();
  return FrameMotion{motion, step, middle_share() * step};
}

Vector6d OdometryPipeline::anchored_part(const Vector6d& motion) const {
  Vector6d part = Vector6d::Zero();
  if (first_velocity_.head<3>().norm() >= config_.anchor_min_rotation)
    part.head<3>() = motion.head<3>();
  if (first_velocity_.tail<3>().norm() >= config_.anchor_min_translation)
    part.tail<3>() = motion.tail<3>();
  return part;
}

Pose OdometryPipeline::settled_pose(std::size_t index) const {
  if (index >= std::min(frames_, kWorldSettlesAfter))
    throw Error("settled_pose: frame " + std::to_string(index) + " is not an early frame");
  // Frame 0's start is the world's origin, whatever the anchor says of the internal frame.
  if (index == 0) return Pose::Identity();
  return orthonormalized(world_from_internal_ * early_starts_[index]);
}

const PointCloud* OdometryPipeline::last_map_frame(Pose& registration_from_frame) const {
  registration_from_frame = pose_;
  return &last_frame();
}

}  // namespace scanmatch
