#include "scanmatch/odometry/mapper2d.hpp"

#include <algorithm>
#include <chrono>

#include "scanmatch/core/error.hpp"

namespace scanmatch {

Mapper2D::Mapper2D(const Mapper2DConfig& config) : config_(config) {
  const auto& names = registration_2d_method_names();
  if (std::find(names.begin(), names.end(), config.registration.method) == names.end())
    throw Error("unknown 2D registration method '" + config.registration.method + "'");
}

Pose2 Mapper2D::add_scan(const Scan2D& scan) {
  stats_ = {};
  stats_.points = scan.points.size();
  ++scans_;
  if (scans_ == 1) {
    previous_ = scan;
    return pose_;
  }
  const Pose2 guess = config_.constant_velocity ? motion_ : Pose2::Identity();
  Pose2 step = guess;
  const auto start = std::chrono::steady_clock::now();
  try {
    const Registration2DResult r = register_scans(scan, previous_, config_.registration, guess);
    const Pose2 correction = guess.inverse() * r.transform;
    if (r.pairs >= 3 && r.transform.matrix().allFinite() &&
        correction.translation().norm() <= config_.max_correction &&
        std::abs(pose2_angle(correction)) <= config_.max_correction_angle) {
      step = r.transform;
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
  // A bridged scan keeps the previous reference unless it is usable itself.
  if (!stats_.bridged || scan.points.size() >= previous_.points.size()) previous_ = scan;
  motion_ = step;
  pose_ = pose_ * step;
  // Re-orthonormalise: chaining thousands of products slowly bends R off SO(2).
  pose_ = pose2(pose_.translation().x(), pose_.translation().y(), pose2_angle(pose_));
  return pose_;
}

}  // namespace scanmatch
