#include "scanmatch/odometry/motion_model.hpp"

#include <algorithm>
#include <cmath>

namespace scanmatch {
namespace {

/// Time-step ratios this close to 1 count as regular: timestamp jitter is not motion.
constexpr double kRegularStep = 0.05;
/// A sensor is steady when its last kSteadySteps time steps lie within kSteadyJitter of their
/// mean: its steps are then its period, and their spread is stamp jitter, not timing. KITTI raw
/// stamps come from a 100 Hz clock, so a 0.1036 s period reads as 0.10 or 0.11 s: scaled by
/// their ratio, the prior of a car at 18 m/s missed by up to 0.2 m (half the frames uncertain).
/// A dropped frame (twice the period) stays a real step; keyframes are never steady.
constexpr std::size_t kSteadySteps = 8;
constexpr double kSteadyJitter = 0.1;

}  // namespace

Pose scaled_motion(const Pose& motion, double factor) {
  return se3_exp(factor * se3_log(motion));
}

Pose turned_about_z(const Pose& motion, double yaw) {
  Pose turned = motion;
  turned.linear() =
      motion.linear() * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return turned;
}

Pose along_an_arc(const Pose& motion, double yaw) {
  Pose turned = turned_about_z(motion, yaw);
  turned.translation() =
      Eigen::AngleAxisd(0.5 * yaw, Eigen::Vector3d::UnitZ()) * motion.translation();
  return turned;
}

MotionModel::MotionModel(const OdometryConfig& config) : config_(config) {}

const MotionPrior& MotionModel::predict(double timestamp, std::size_t frames) {
  step_ = frames > 0 ? timestamp - last_timestamp_ : 0.0;
  steady_period_ = steady_period();
  if (step_ > 0.0) remember_step(step_);
  if (frames > 0 && timestamp > last_timestamp_) frame_period_ = timestamp - last_timestamp_;
  last_timestamp_ = timestamp;

  prior_ = MotionPrior{};
  prior_.motion = velocity_;
  if (!config_.constant_velocity) return prior_;  // the previous pose is the guess
  // Frame 1 has no motion yet (the identity), and a bridged frame's motion was not measured.
  prior_.uncertain = frames == 1 || previous_bridged_ || previous_missed_;
  if (config_.time_scaled_prior && frames >= 2) scale_by_time_step();
  // A sharp turn is guessed as badly as it is large: a hand-held sweep reverses at any time.
  if (rotation_angle(prior_.motion) > config_.uncertain_rotation) prior_.uncertain = true;
  return prior_;
}

void MotionModel::scale_by_time_step() {
  if (!(step_ > 0.0) || !(velocity_period_ > 0.0)) {
    prior_.uncertain = true;  // no usable stamps: the step is unknown
    return;
  }
  const double ratio = as_period(step_) / as_period(velocity_period_);
  if (std::abs(ratio - 1.0) <= kRegularStep) return;
  if (ratio > config_.max_step_ratio || ratio < 1.0 / config_.max_step_ratio) {
    // A gap (dropped frames) or a burst: scale within bounds, but trust it less.
    prior_.uncertain = true;
    prior_.gap = ratio > config_.max_step_ratio;
    prior_.scale = std::clamp(ratio, 1.0 / config_.max_step_ratio, config_.max_step_ratio);
  } else {
    prior_.scale = ratio;
  }
  prior_.motion = scaled_motion(velocity_, prior_.scale);
}

double MotionModel::steady_period() const {
  if (recent_steps_.size() < kSteadySteps) return 0.0;
  const auto [lowest, highest] = std::minmax_element(recent_steps_.begin(), recent_steps_.end());
  double sum = 0.0;
  for (double s : recent_steps_) sum += s;
  const double mean = sum / static_cast<double>(recent_steps_.size());
  return *lowest >= (1.0 - kSteadyJitter) * mean && *highest <= (1.0 + kSteadyJitter) * mean ? mean
                                                                                             : 0.0;
}

bool MotionModel::within_steady_period(double step) const {
  return steady_period_ > 0.0 && std::abs(step / steady_period_ - 1.0) <= kSteadyJitter;
}

double MotionModel::as_period(double step) const {
  return within_steady_period(step) ? steady_period_ : step;
}

void MotionModel::remember_step(double step) {
  // A steady sensor's odd step (a dropped frame) is not its period; a lasting change is.
  const bool odd = steady_period_ > 0.0 && !within_steady_period(step);
  if (odd && ++odd_steps_ < kSteadySteps) return;
  odd_steps_ = 0;
  recent_steps_.push_back(step);
  if (recent_steps_.size() > kSteadySteps) recent_steps_.pop_front();
}

bool MotionModel::within_gate(const Pose& predicted, const Pose& estimate) const {
  if (!to_matrix(estimate).allFinite()) return false;
  const double widen = prior_.uncertain ? config_.uncertain_jump_scale : 1.0;
  const double radius = widen * config_.max_jump, angle = widen * config_.max_jump_angle;
  const auto near = [&](const Pose& centre) {
    const Pose jump = centre.inverse() * estimate;
    return jump.translation().norm() <= radius && rotation_angle(jump) <= angle;
  };
  if (near(predicted)) return true;
  // After a long time step, around the prior carried along an arc to the estimate's own heading: a
  // car that turned 47 deg between keyframes 10 m apart ends 4 m beside the straight prior.
  if (prior_.turn_reach > 0.0) {
    const Pose last = predicted * prior_.motion.inverse();
    const Pose turn = prior_.motion.inverse() * (last.inverse() * estimate);
    if (near(last * along_an_arc(prior_.motion, to_xyz_rpy(turn)(5)))) return true;
  }
  if (!prior_.gap) return false;
  // Fractions of the motion from the last pose, spaced closer than the radius (riverside02's car
  // waited 16-21 s at keyframes 57-59, where the scaled prior put it 9 m on).
  const Pose last = predicted * prior_.motion.inverse();
  const int pieces = static_cast<int>(std::ceil(prior_.motion.translation().norm() / radius));
  for (int k = 0; k < pieces; ++k)
    if (near(last * scaled_motion(prior_.motion, static_cast<double>(k) / pieces))) return true;
  return false;
}

bool MotionModel::moving(const Pose& motion, double factor) const {
  return motion.translation().norm() >= factor * config_.deskew_min_translation ||
         rotation_angle(motion) >= factor * config_.deskew_min_rotation;
}

void MotionModel::record(const Pose& motion, bool bridged) {
  const Pose miss = prior_.motion.inverse() * motion;
  previous_missed_ = !bridged && (miss.translation().norm() > config_.prior_miss_distance ||
                                  rotation_angle(miss) > config_.prior_miss_angle);
  previous_bridged_ = bridged;
  if (!bridged) velocity_period_ = step_ > 0.0 ? step_ : velocity_period_;
  if (!bridged && config_.constant_velocity) velocity_ = motion;
}

}  // namespace scanmatch
