#include "scanmatch/odometry/mapper2d.hpp"

#include <algorithm>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/planar/correlative_search.hpp"

namespace scanmatch {

Mapper2D::Mapper2D(const Mapper2DConfig& config) : config_(config) {
  check_registration_2d_options(config.registration);
  if (!(config.wide_search_angle >= 0.0) || !(config.wide_search_below >= 0.0) ||
      !(config.full_turn_search_below >= 0.0))
    throw Error(
        "map2d: wide_search_angle, wide_search_below and full_turn_search_below must not be "
        "negative");
  if (!(config.open_step_window >= 0.0) || !(config.open_step_margin >= 0.0) ||
      !(config.open_step_spread >= 0.0) || !(config.open_step_prior_distance >= 0.0))
    throw Error(
        "map2d: open_step_window, open_step_margin, open_step_spread and "
        "open_step_prior_distance must not be negative");
}

bool Mapper2D::plausible_correction(const Pose2& correction, bool whole_turn) const {
  // Never rejects what the correlative search was asked to look for.
  const Registration2DOptions& r = config_.registration;
  const bool search = r.search_window > 0.0;
  const double searched_angle =
      whole_turn ? M_PI : std::max(r.search_angle, config_.wide_search_angle);
  return correction.translation().norm() <=
             std::max(config_.max_correction, search ? r.search_window + 0.5 : 0.0) &&
         std::abs(pose2_angle(correction)) <=
             std::max(config_.max_correction_angle, search ? searched_angle + 0.2 : 0.0);
}

namespace {

/// The share of a scan's points within 15 cm of the reference's surfaces (filled between beams as
/// the search fills them), at a pose in the reference's frame.
class ScanFit {
 public:
  ScanFit(const Scan2D& reference, double fill_gap)
      : surfaces_(filled_surfaces(reference, fill_gap, 0.05)), tree_(surfaces_) {}
  double operator()(const Scan2D& scan, const Pose2& pose) const {
    if (scan.points.empty()) return 0.0;
    std::size_t near = 0, index = 0;
    double squared = 0.0;
    for (const Eigen::Vector2d& p : scan.points)
      near += tree_.nearest(pose * p, 0.15 * 0.15, index, squared);
    return static_cast<double>(near) / static_cast<double>(scan.points.size());
  }

 private:
  std::vector<Eigen::Vector2d> surfaces_;
  KdTree2 tree_;
};

/// Each point moved to where it would have been seen from the pose at the first beam, the sensor
/// moving by `motion` every `interval` seconds. Misses carry no times and stay as measured.
Scan2D deskewed(const Scan2D& scan, const Pose2& motion, double interval) {
  Scan2D out = scan;
  const double dx = motion.translation().x(), dy = motion.translation().y(),
               dtheta = pose2_angle(motion);
  for (std::size_t i = 0; i < out.points.size(); ++i) {
    const double s = scan.times[i] / interval;
    out.points[i] = pose2(s * dx, s * dy, s * dtheta) * scan.points[i];
  }
  return out;
}

}  // namespace

Pose2 Mapper2D::prior_along_open_direction(const Scan2D& current, const Scan2D& reference,
                                           const Pose2& registered, const Pose2& guess) {
  if (!registered.matrix().allFinite()) return registered;
  const CorrelativeSpread spread =
      correlative_spread(current, reference, registered, config_.open_step_window, kStepSpreadAngle,
                         kStepSpreadResolution, config_.registration.search_fill_gap,
                         config_.open_step_margin, Eigen::Vector2d(guess.translation()));
  if (spread.poses == 0 || !spread.second_moment.allFinite()) return registered;
  const SpreadAxis axis = widest_spread(spread);
  if (axis.rms < config_.open_step_spread) return registered;
  if ((spread.nearest.translation() - guess.translation()).norm() >
      config_.open_step_prior_distance)
    return registered;
  // Along the open direction only: across it the registration is as good as the scans. Within a
  // cell of the registered pose the scans' answer stands as it is.
  const Eigen::Vector2d& open = axis.direction;
  const double along = open.dot(spread.nearest.translation() - registered.translation());
  if (std::abs(along) < kStepSpreadResolution) return registered;
  const Eigen::Vector2d moved = registered.translation() + along * open;
  const Pose2 shifted = pose2(moved.x(), moved.y(), pose2_angle(registered));
  // Registered again from there for the rotation and the across direction (the spread's axis is
  // a cell-resolution estimate, a few degrees off: a metre along it drifts centimetres across),
  // keeping only the across part of what the registration moves.
  Registration2DOptions fine = config_.registration;
  fine.search_window = 0.0;
  Pose2 refined = shifted;
  try {
    refined = register_scans(current, reference, fine, shifted).transform;
  } catch (const Error&) {
    // Too few usable points to register again: the shifted pose stands.
  }
  if (!refined.matrix().allFinite()) refined = shifted;
  const Eigen::Vector2d across(-open.y(), open.x());
  const Eigen::Vector2d result =
      moved + across * across.dot(refined.translation() - shifted.translation());
  stats_.open_step_from_prior = true;
  return pose2(result.x(), result.y(), pose2_angle(refined));
}

Pose2 Mapper2D::add_scan(const Scan2D& input, double timestamp) {
  stats_ = {};
  stats_.points = input.points.size();
  ++scans_;
  const double interval = timestamp - last_timestamp_;
  last_timestamp_ = timestamp;
  const bool timed = config_.deskew && input.times.size() == input.points.size();
  if (scans_ == 1) {
    keyframe_ = last_scan_ = input;
    return pose_;
  }
  const Pose2 predicted = pose_ * (config_.constant_velocity ? motion_ : Pose2::Identity());
  const Pose2 guess = keyframe_pose_.inverse() * predicted;  // current in the keyframe's frame
  // Both scans are deskewed by one velocity, the last step's motion. Deskewing each scan by the
  // step before it (the keyframe by an older one) made the next registration see the difference
  // of two velocity errors and over-correct it: the poses oscillated and diverged on room-2d. A
  // second pass with this step's own motion changed nothing measurable.
  const bool deskew = timed && keyframe_.times.size() == keyframe_.points.size() &&
                      motion_interval_ > 0.0 && interval > 0.0;
  Scan2D current_deskewed, keyframe_deskewed;
  if (deskew) {
    current_deskewed = deskewed(input, motion_, motion_interval_);
    keyframe_deskewed = deskewed(keyframe_, motion_, motion_interval_);
  }
  const Scan2D& current = deskew ? current_deskewed : input;
  const Scan2D& reference = deskew ? keyframe_deskewed : keyframe_;
  Pose2 relative = guess;
  bool whole_turn = false;
  const Stopwatch stopwatch;
  try {
    Registration2DResult r = register_scans(current, reference, config_.registration, guess);
    const Registration2DOptions& o = config_.registration;
    const bool wide = config_.wide_search_angle > o.search_angle;
    if (o.search_window > 0.0 && (wide || config_.full_turn_search_below > 0.0)) {
      // A turn beyond the search's angle window leaves most points off the reference.
      const ScanFit fit(reference, o.search_fill_gap);
      double best = fit(current, r.transform);
      // The wider search wins only where clearly more points fit: it finds more false matches.
      const auto search_wider = [&](double angle) {
        Registration2DOptions wider = o;
        wider.search_angle = angle;
        const Registration2DResult w = register_scans(current, reference, wider, guess);
        const double fitted = fit(current, w.transform);
        if (fitted <= best + 0.05) return false;
        r = w;
        best = fitted;
        return true;
      };
      if (wide && best < config_.wide_search_below) search_wider(config_.wide_search_angle);
      stats_.weak_fit = best < config_.full_turn_search_below;
      if (stats_.weak_fit && std::max(o.search_angle, config_.wide_search_angle) < M_PI)
        whole_turn = search_wider(M_PI);
    }
    if (config_.constant_velocity && config_.open_step_window > 0.0)
      r.transform = prior_along_open_direction(current, reference, r.transform, guess);
    const Pose2 correction = guess.inverse() * r.transform;
    if (r.pairs >= 3 && r.transform.matrix().allFinite() &&
        plausible_correction(correction, whole_turn)) {
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
  stats_.ms = stopwatch.ms();
  Pose2 pose = keyframe_pose_ * relative;
  // Re-orthonormalise: chaining thousands of products slowly bends R off SO(2).
  pose = pose2(pose.translation().x(), pose.translation().y(), pose2_angle(pose));
  motion_ = pose_.inverse() * pose;
  motion_interval_ = interval;
  pose_ = pose;
  // For the map: deskewed by the motion into it (the best estimate of its own until the next).
  last_scan_ = timed && interval > 0.0 ? deskewed(input, motion_, interval) : input;
  const bool scan_to_scan = config_.keyframe_distance <= 0.0 && config_.keyframe_angle <= 0.0;
  const bool far =
      scan_to_scan ||
      (config_.keyframe_distance > 0.0 &&
       relative.translation().norm() >= config_.keyframe_distance) ||
      (config_.keyframe_angle > 0.0 && std::abs(pose2_angle(relative)) >= config_.keyframe_angle);
  // A bridged scan becomes the reference only when the old one is no better. Kept as measured:
  // it is deskewed anew with each step's velocity.
  if (far && (!stats_.bridged || input.points.size() >= keyframe_.points.size())) {
    keyframe_ = input;
    keyframe_pose_ = pose_;
  }
  return pose_;
}

}  // namespace scanmatch
