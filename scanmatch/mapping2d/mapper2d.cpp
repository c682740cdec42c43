#include "scanmatch/mapping2d/mapper2d.hpp"

#include <algorithm>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/geometry/kdtree.hpp"
#include "scanmatch/registration/planar/correlative_search.hpp"
#include "scanmatch/registration/planar/reference2d.hpp"

namespace scanmatch {

Mapper2D::Mapper2D(const Mapper2DConfig& config) : config_(config) {
  check_registration_2d_options(config.registration);
  if (!(config.wide_search_angle >= 0.0) || !(config.wide_search_below >= 0.0) ||
      !(config.full_turn_search_below >= 0.0))
    throw Error(
        "map2d: wide_search_angle, wide_search_below and full_turn_search_below must not be "
        "negative");
  if (!(config.open_step_window >= 0.0) || !(config.open_step_margin >= 0.0) ||
      !(config.open_step_spread >= 0.0) || !(config.open_step_prior_distance >= 0.0) ||
      config.open_step_speed_steps < 0)
    throw Error(
        "map2d: open_step_window, open_step_margin, open_step_spread, open_step_prior_distance "
        "and open_step_speed_steps must not be negative");
  if (!(config.long_search_window >= 0.0) || !(config.long_search_below >= 0.0))
    throw Error("map2d: long_search_window and long_search_below must not be negative");
  if (!(config.reference_fit_below >= 0.0) || config.max_unfit_references_skipped < 0)
    throw Error("map2d: reference_fit_below and max_unfit_references_skipped must not be negative");
  if (!(config.unfit_max_correction >= 0.0) || !(config.unfit_max_correction_angle >= 0.0))
    throw Error("map2d: unfit_max_correction and unfit_max_correction_angle must not be negative");
  if (config.unfit_steady_steps < 1) throw Error("map2d: unfit_steady_steps must be at least 1");
  if (config.submap_scans < 1 || !(config.submap_link_fit >= 0.0 && config.submap_link_fit <= 1.0))
    throw Error("map2d: submap_scans must be at least 1 and submap_link_fit in [0, 1]");
}

bool Mapper2D::plausible_correction(const Pose2& correction, bool whole_turn, double window) const {
  // Never rejects what the correlative search was asked to look for.
  const Registration2DOptions& r = config_.registration;
  const bool search = window > 0.0;
  const double searched_angle =
      whole_turn ? M_PI : std::max(r.search_angle, config_.wide_search_angle);
  // The window is a square: its corners lie sqrt(2) times as far.
  return correction.translation().norm() <=
             std::max(config_.max_correction, search ? window * M_SQRT2 + 0.5 : 0.0) &&
         std::abs(pose2_angle(correction)) <=
             std::max(config_.max_correction_angle, search ? searched_angle + 0.2 : 0.0);
}

namespace {

/// The long search also wins where its search scores this much more (a share of the best
/// possible) and no fewer points fit: along a corridor the share within 15 cm barely tells a step
/// slid short from the true one (orebro 27 -> 28: 0.80 against 0.82), the smoothed score does
/// (0.57 against 0.63).
constexpr double kLongSearchMargin = 0.03;

/// The share of a scan's points within 15 cm of the reference's surfaces (filled between beams as
/// the search fills them), at a pose in the reference's frame.
class ScanFit {
 public:
  /// `surfaces`: filled_surfaces of the reference (and of the older ones in its frame).
  explicit ScanFit(std::vector<Eigen::Vector2d> surfaces)
      : surfaces_(std::move(surfaces)), tree_(surfaces_) {}
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

Pose2 Mapper2D::prior_along_open_direction(const Scan2D& current, const Reference2D& reference,
                                           const CorrelativeSpread& spread, const Pose2& registered,
                                           const Pose2& guess) {
  if (!registered.matrix().allFinite()) return registered;
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
  fine.search_window = 0.0;  // the method's own coarse stage, as without the search
  Pose2 refined = shifted;
  try {
    refined = registration_2d_method(fine.method).run(current, reference, fine, shifted).transform;
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

bool Mapper2D::steady_motion() const {
  const auto steps = static_cast<std::size_t>(config_.unfit_steady_steps);
  if (!config_.constant_velocity || recent_motions_.size() < steps) return false;
  return std::all_of(recent_motions_.end() - static_cast<std::ptrdiff_t>(steps),
                     recent_motions_.end(),
                     [&](const Pose2& m) { return !departs_from_prior(motion_.inverse() * m); });
}

bool Mapper2D::departs_from_prior(const Pose2& correction) const {
  return (config_.unfit_max_correction > 0.0 &&
          correction.translation().norm() > config_.unfit_max_correction) ||
         (config_.unfit_max_correction_angle > 0.0 &&
          std::abs(pose2_angle(correction)) > config_.unfit_max_correction_angle);
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
  bool whole_turn = false, search_pose_fits = false;
  const Stopwatch stopwatch;
  try {
    const Registration2DOptions& o = config_.registration;
    Registration2DResult r;
    if (o.search_window > 0.0) {
      // One likelihood grid and one prepared reference serve every search and refinement of
      // this step.
      const Reference2D prepared(reference);
      // The searches score against the reference and, half and half, the older references
      // still held (submap_scans): on the last scan alone ACES's scan 316, down a corridor,
      // scored standing still 0.74 against 0.62 at the true 1.16 m step.
      std::vector<Eigen::Vector2d> newest =
          filled_surfaces(reference, o.search_fill_gap, o.search_resolution);
      std::vector<Eigen::Vector2d> older;
      for (const auto& [surfaces, older_pose] : older_references_) {
        const Pose2 into = keyframe_pose_.inverse() * older_pose;
        for (const Eigen::Vector2d& q : surfaces) older.push_back(into * q);
      }
      const CorrelativeGrid grid(newest, older, o.search_resolution);
      // Each search's score (correlative_match's share) beside its refined pose.
      double score = 0.0;
      const Eigen::Vector2d window = Eigen::Vector2d::Constant(o.search_window);
      // Each wider search looks again at no earlier window (same poses, far fewer scores).
      CorrelativeSearches searches(current, grid, guess);
      CorrelativeMatch match = searches.match(window, o.search_angle);
      score = match.score;
      r = refine_searched(current, prepared, o, match.pose);
      // A turn beyond the search's angle window leaves most points off the reference.
      newest.insert(newest.end(), older.begin(), older.end());
      const ScanFit fit(std::move(newest));
      double best = fit(current, r.transform);
      // A wider search wins only where clearly more points fit: it finds more false matches.
      // With `score_margin`, also where its search scored that much more and as many points fit.
      const auto search_wider = [&](const Eigen::Vector2d& wider_window, double angle,
                                    double score_margin = 1.0) {
        // Every wider window here holds the first search's, so its best scores at least as
        // high: poses below the best score so far need no look (the bounds prune from the
        // start), and where none reaches it the best so far stands.
        match = searches.match(wider_window, angle, std::clamp(score, 0.0, 1.0));
        if (!match.found) return false;
        const Registration2DResult w = refine_searched(current, prepared, o, match.pose);
        const double fitted = fit(current, w.transform);
        if (fitted <= best + 0.05 && !(match.score > score + score_margin && fitted >= best))
          return false;
        r = w;
        best = fitted;
        score = match.score;
        return true;
      };
      const bool wide = config_.wide_search_angle > o.search_angle;
      if (wide && best < config_.wide_search_below) search_wider(window, config_.wide_search_angle);
      stats_.weak_fit = best < config_.full_turn_search_below;
      if (stats_.weak_fit && std::max(o.search_angle, config_.wide_search_angle) < M_PI)
        whole_turn = search_wider(window, M_PI);
      const bool open_step = config_.constant_velocity && config_.open_step_window > 0.0;
      CorrelativeSpread spread;
      const auto spread_at = [&](const Pose2& at) {
        spread = correlative_spread(current, reference, at, config_.open_step_window,
                                    kStepSpreadAngle, kStepSpreadResolution, o.search_fill_gap,
                                    config_.open_step_margin, Eigen::Vector2d(guess.translation()));
      };
      if (open_step && r.transform.matrix().allFinite()) spread_at(r.transform);
      // The robot may have moved farther from the prior than the window reaches: few points fit,
      // the scans fit all along the window (a corridor), or the step already departs far from
      // the prior (a stop, a turn on the spot: the prior is wrong here and may be by more).
      const bool open = spread.poses > 0 && spread.second_moment.allFinite() &&
                        widest_spread(spread).rms >= config_.open_step_spread;
      const Pose2 departure = guess.inverse() * r.transform;
      const bool far_from_prior = departure.translation().norm() > 0.5 * o.search_window ||
                                  std::abs(pose2_angle(departure)) > 0.5 * o.search_angle;
      const bool weak = best < config_.long_search_below;
      if (config_.long_search_window > o.search_window && (weak || open || far_from_prior)) {
        stats_.long_search = true;
        // Where the points fit well the share within 15 cm saturates and the score decides. Far
        // along the keyframe's heading only (a wheeled robot drives forward): sideways, at a
        // corner, a corridor entered one door further fits as well (corridor-2d scan 82).
        stats_.long_search_won = search_wider(
            Eigen::Vector2d(config_.long_search_window, o.search_window),
            std::max(o.search_angle, config_.wide_search_angle), weak ? 1.0 : kLongSearchMargin);
      }
      stats_.fit = best;
      // The method failed from the search's pose (too few pairs after a turn, say) and the
      // search's pose was kept: it stands where it fits better than the motion prior would.
      search_pose_fits = r.search_pose_kept && best > fit(current, guess);
      // After a turn the constant-velocity prior turns on: where the scans fit but leave the
      // length open and no fitting translation lies near that prior, straight on at the recent
      // speed (open_step_speed_steps).
      Pose2 prior = guess;
      if (open_step && open && !stats_.weak_fit && !stats_.long_search_won &&
          config_.open_step_speed_steps > 0 && !recent_motions_.empty() &&
          (spread.nearest.translation() - guess.translation()).norm() >
              config_.open_step_prior_distance) {
        const std::size_t n = std::min(recent_motions_.size(),
                                       static_cast<std::size_t>(config_.open_step_speed_steps));
        std::vector<double> lengths;
        for (auto m = recent_motions_.end() - static_cast<std::ptrdiff_t>(n);
             m != recent_motions_.end(); ++m)
          lengths.push_back(m->translation().norm());
        const auto middle = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
        std::nth_element(lengths.begin(), middle, lengths.end());
        // From the last scan's pose, along the heading registered for this one.
        const Pose2 last = keyframe_pose_.inverse() * pose_;
        const double turn = pose2_angle(last.inverse() * r.transform);
        prior = last * pose2(*middle * std::cos(turn), *middle * std::sin(turn), turn);
        spread = correlative_spread(current, reference, r.transform, config_.open_step_window,
                                    kStepSpreadAngle, kStepSpreadResolution, o.search_fill_gap,
                                    config_.open_step_margin, Eigen::Vector2d(prior.translation()));
      }
      // The prior chooses along an open step only where it was not shown wrong by the long
      // search.
      if (open_step && !stats_.long_search_won && spread.poses > 0)
        r.transform = prior_along_open_direction(current, prepared, spread, r.transform, prior);
    } else {
      r = register_scans(current, reference, o, guess);
      if (config_.constant_velocity && config_.open_step_window > 0.0 &&
          r.transform.matrix().allFinite()) {
        const CorrelativeSpread spread =
            correlative_spread(current, reference, r.transform, config_.open_step_window,
                               kStepSpreadAngle, kStepSpreadResolution, o.search_fill_gap,
                               config_.open_step_margin, Eigen::Vector2d(guess.translation()));
        r.transform =
            prior_along_open_direction(current, Reference2D(reference), spread, r.transform, guess);
      }
    }
    const Pose2 correction = guess.inverse() * r.transform;
    // A scan that barely fits its reference may not move a steady motion far from its prior.
    stats_.unfit = stats_.fit >= 0.0 && stats_.fit < config_.reference_fit_below;
    stats_.steady_prior = stats_.unfit && departs_from_prior(correction) && steady_motion();
    if ((r.pairs >= 3 || search_pose_fits) && r.transform.matrix().allFinite() &&
        !stats_.steady_prior &&
        plausible_correction(
            correction, whole_turn,
            stats_.long_search ? config_.long_search_window : config_.registration.search_window)) {
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
  recent_motions_.push_back(motion_);
  if (recent_motions_.size() >
      static_cast<std::size_t>(std::max(config_.open_step_speed_steps, config_.unfit_steady_steps)))
    recent_motions_.pop_front();
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
  // Its own pose and motion stand (the next scan's prior starts from them): on freiburg-campus
  // a prior from the reference instead, by the motion before, did worse (loop-closed ATE 3.8 ->
  // 4.5 m, odometry 10 -> 53 m).
  stats_.unfit_reference =
      stats_.unfit && unfit_references_skipped_ < config_.max_unfit_references_skipped;
  // The scene has moved on from the old reference (as many unfit scans skipped as allowed): a
  // scan bridged by a steady prior replaces it, or the next scans register ever farther from it
  // (freiburg-campus 498 onto 489, 9 m back: 11 deg off). A prior that is not steady may be
  // wrong (1331-1332 turned the way the robot did not): the next scan registers onto the older
  // reference and takes back the heading.
  const bool reference_stale = stats_.steady_prior && !stats_.unfit_reference;
  unfit_references_skipped_ = stats_.unfit_reference ? unfit_references_skipped_ + 1 : 0;
  // A bridged scan becomes the reference only when the old one is no better or is stale. Kept as
  // measured: it is deskewed anew with each step's velocity.
  if (far && !stats_.unfit_reference &&
      (!stats_.bridged || reference_stale || input.points.size() >= keyframe_.points.size())) {
    // The older references stay in the search while every step joining them fit well: a weak
    // step's error would double the walls the next scans search against.
    if (stats_.bridged || stats_.fit < config_.submap_link_fit) {
      older_references_.clear();
    } else if (config_.submap_scans > 1) {
      // Filled once here, not at every step that searches against it.
      const Registration2DOptions& o = config_.registration;
      older_references_.emplace_front(
          filled_surfaces(keyframe_, o.search_fill_gap, o.search_resolution), keyframe_pose_);
      if (older_references_.size() >= static_cast<std::size_t>(config_.submap_scans))
        older_references_.pop_back();
    }
    keyframe_ = input;
    keyframe_pose_ = pose_;
  }
  return pose_;
}

}  // namespace scanmatch
