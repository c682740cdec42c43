#include "scanmatch/odometry/mapper2d.hpp"

#include <algorithm>
#include <chrono>

#include "scanmatch/core/error.hpp"

namespace scanmatch {

Mapper2D::Mapper2D(const Mapper2DConfig& config) : config_(config) {
  check_registration_2d_method(config.registration.method);
}

Pose2 Mapper2D::add_scan(const Scan2D& scan) {
  stats_ = {};
  stats_.points = scan.points.size();
  ++scans_;
  if (scans_ == 1) {
    keyframe_ = scan;
    return pose_;
  }
  const Pose2 predicted = pose_ * (config_.constant_velocity ? motion_ : Pose2::Identity());
  const Pose2 guess = keyframe_pose_.inverse() * predicted;  // current in the keyframe's frame
  Pose2 relative = guess;
  const auto start = std::chrono::steady_clock::now();
  try {
    const Registration2DResult r = register_scans(scan, keyframe_, config_.registration, guess);
    const Pose2 correction = guess.inverse() * r.transform;
    if (r.pairs >= 3 && r.transform.matrix().allFinite() &&
        correction.translation().norm() <= config_.max_correction &&
        std::abs(pose2_angle(correction)) <= config_.max_correction_angle) {
      relative = r.transform;
      stats_.iterations = r.iterations;
      stats_.pairs = r.pairs;
      stats_.error = r.error;
    } else {
      stats_.bridged = true;
    }
  } catch (const Error&) {
    stats_.bridged = true;  // too few points in one of the scans
  }
  stats_.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  Pose2 pose = keyframe_pose_ * relative;
  // Re-orthonormalise: chaining thousands of products slowly bends R off SO(2).
  pose = pose2(pose.translation().x(), pose.translation().y(), pose2_angle(pose));
  motion_ = pose_.inverse() * pose;
  pose_ = pose;
  const bool scan_to_scan = config_.keyframe_distance <= 0.0 && config_.keyframe_angle <= 0.0;
  const bool far =
      scan_to_scan ||
      (config_.keyframe_distance > 0.0 &&
       relative.translation().norm() >= config_.keyframe_distance) ||
      (config_.keyframe_angle > 0.0 && std::abs(pose2_angle(relative)) >= config_.keyframe_angle);
  // A bridged scan becomes the reference only when the old one is no better.
  if (far && (!stats_.bridged || scan.points.size() >= keyframe_.points.size())) {
    keyframe_ = scan;
    keyframe_pose_ = pose_;
  }
  return pose_;
}

}  // namespace scanmatch
