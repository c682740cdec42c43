// 2D loop closure's orchestration: keyframes, odometry edges, searches, optimizations
// (loop_closure2d.hpp).
#include "scanmatch/mapping/loop_closure2d.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include <tbb/parallel_for.h>

#include "scanmatch/core/error.hpp"
#include "scanmatch/core/stopwatch.hpp"
#include "scanmatch/mapping/edge_information.hpp"
#include "scanmatch/mapping/loop_candidates.hpp"
#include "scanmatch/registration/planar/correlative_search.hpp"
#include "scanmatch/registration/planar/registration2d.hpp"

namespace scanmatch {
namespace {

// How far `change` moves points 5 m away, at most, m: the scale optimize_above and recheck_above
// are given in.
double moved_at_5m(const Pose2& change) {
  return change.translation().norm() + 5.0 * std::abs(pose2_angle(change));
}

}  // namespace

void check_loop_closure_2d_options(const LoopClosure2DOptions& options) {
  check_registration_2d_method(options.verification.method);
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(options.odometry_sigma_xy) || !positive(options.odometry_sigma_theta) ||
      !positive(options.loop_sigma_xy) || !positive(options.loop_sigma_theta))
    throw Error("loop closure: the edge standard deviations must be positive");
  if (!positive(options.verification.pair_distance) ||
      !positive(options.verification.search_window) ||
      !positive(options.verification.search_resolution))
    throw Error("loop closure: pair distance, search window and resolution must be positive");
  if (!(options.keyframe_distance >= 0.0) || !(options.keyframe_angle >= 0.0))
    throw Error("loop closure: keyframe thresholds must not be negative");
  if (!(options.odometry_spread_window >= 0.0) || !(options.odometry_spread_margin >= 0.0) ||
      !(options.odometry_spread_normal >= 0.0) || !(options.open_step_spread >= 0.0))
    throw Error(
        "loop closure: the odometry spread's window, margin, normal and open spreads must not "
        "be negative");
  if (!(options.rotation_open_ratio >= 0.0) || !(options.rotation_open_min_turn >= 0.0) ||
      !(options.rotation_open_sigma_theta > 0.0))
    throw Error(
        "loop closure: rotation_open_ratio and rotation_open_min_turn must not be negative and "
        "rotation_open_sigma_theta must be positive");
  if (!(options.unfit_step_information > 0.0 && options.unfit_step_information <= 1.0))
    throw Error("loop closure: unfit_step_information must be in (0, 1]");
  if (!(options.optimize_above >= 0.0))
    throw Error("loop closure: optimize_above must not be negative");
  if (!(options.max_error_per_floor >= 0.0) || !std::isfinite(options.max_error_per_floor))
    throw Error("loop closure: max_error_per_floor must be finite and not negative (0: off)");
  if (std::isnan(options.registration_reach))
    throw Error("loop closure: registration_reach must be a number (negative: off)");
  if (!(options.widening_per_weak_step >= 0.0) || !std::isfinite(options.widening_per_weak_step) ||
      !(options.max_doubt_widening >= 0.0) || !std::isfinite(options.max_doubt_widening))
    throw Error(
        "loop closure: widening_per_weak_step and max_doubt_widening must be finite and not "
        "negative");
  if (!(options.recheck_above >= 0.0))
    throw Error("loop closure: recheck_above must not be negative");
  if (!(options.verification.min_search_score >= 0.0 &&
        options.verification.min_search_score <= 1.0))
    throw Error("loop closure: min_search_score must be in [0, 1]");
  if (!(options.verification.max_shifted_fraction >= 0.0))
    throw Error("loop closure: max_shifted_fraction must not be negative (0: not checked)");
  if (!(options.sliding_information_kept >= 0.0 && options.sliding_information_kept <= 1.0))
    throw Error("loop closure: sliding_information_kept must be in [0, 1]");
}

LoopKeyframes2D::LoopKeyframes2D(const LoopClosure2DOptions& options) : options_(options) {
  check_loop_closure_2d_options(options);
}

KeyframeStep2D LoopKeyframes2D::add_scan(const Scan2D& scan, const Pose2& odometry_pose,
                                         bool weak_fit, bool unfit) {
  const Stopwatch stopwatch;
  weak_fit_since_keyframe_ = weak_fit_since_keyframe_ || weak_fit;
  unfit_since_keyframe_ = unfit_since_keyframe_ || unfit;
  weak_steps_ += weak_fit;
  KeyframeStep2D step;
  // A non-finite odometry pose would poison the graph: hold the last one instead.
  step.odometry = odometry_pose;
  if (!step.odometry.matrix().allFinite())
    step.odometry = have_keyframe_ ? keyframe_odometry_ * last_offset_ : Pose2::Identity();
  step.keyframe = !have_keyframe_;
  std::optional<OdometryInformation> information;
  if (have_keyframe_) {
    step.measurement = keyframe_odometry_.inverse() * step.odometry;
    const Pose2& motion = step.measurement;
    step.keyframe = motion.translation().norm() >= options_.keyframe_distance ||
                    std::abs(pose2_angle(motion)) >= options_.keyframe_angle;
    // A scan whose step the scans leave open becomes a keyframe however little the odometry
    // moved: a slid step is short, and only a node of its own lets the graph stretch it back.
    if (step.keyframe ||
        (options_.odometry_spread_window > 0.0 && options_.open_steps_are_keyframes)) {
      information = odometry_information(keyframe_points_, scan, motion);
      step.keyframe = step.keyframe || information->open;
    }
    // Only keyframe steps: the rotation test searches 160 degrees.
    if (step.keyframe) {
      loosen_open_rotation(*information, keyframe_points_, scan, motion, weak_fit_since_keyframe_);
      step.information = information->information;
      if (unfit_since_keyframe_) step.information *= options_.unfit_step_information;
      step.open = information->open;
      step.rotation_open = information->rotation_open;
      step.pairing_error = pairing_error_2d(scan, keyframe_points_, step.measurement,
                                            options_.verification.pair_distance);
    }
  }
  if (step.keyframe) {
    step.weak_steps = weak_steps_;
    step.descriptor = make_place_descriptor(scan, options_.descriptor);
    keyframe_points_ = scan;
    keyframe_odometry_ = step.odometry;
    have_keyframe_ = true;
    weak_fit_since_keyframe_ = false;
    unfit_since_keyframe_ = false;
  }
  last_offset_ = keyframe_odometry_.inverse() * step.odometry;
  step.offset = last_offset_;
  step.ms = stopwatch.ms();
  return step;
}

LoopClosure2D::LoopClosure2D(const LoopClosure2DOptions& options)
    : options_(options), graph_(options.graph), keyframer_(options) {
  options_.search_every = std::max<std::size_t>(options_.search_every, 1);
}

bool LoopClosure2D::add_scan(const Scan2D& scan, const Pose2& odometry_pose, bool weak_fit,
                             bool unfit) {
  return add_step(scan, keyframer_.add_scan(scan, odometry_pose, weak_fit, unfit));
}

bool LoopClosure2D::add_step(const Scan2D& scan, const KeyframeStep2D& step) {
  const Stopwatch stopwatch;
  if (keyframes_.empty() && !step.keyframe)
    throw Error("loop closure: the first scan's step must make it a keyframe");
  if (step.keyframe) {
    Keyframe k;
    k.scan = scans();
    k.points = scan;
    k.odometry = step.odometry;
    k.weak_steps = step.weak_steps;
    const std::size_t index = keyframes_.size();
    if (index == 0) {
      graph_.graph().add_node(step.odometry);
      keyframes_.push_back(std::move(k));
    } else {
      const Keyframe& previous = keyframes_.back();
      k.pairing_error = step.pairing_error;
      k.path = previous.path + step.measurement.translation().norm();
      graph_.graph().add_node(graph().pose(index - 1) * step.measurement);
      graph_.graph().add_edge(index - 1, index, step.measurement, step.information,
                              EdgeKind::kOdometry);
      if (step.open) ++counts_.open_odometry_edges;
      k.rotation_open = step.rotation_open;
      if (k.rotation_open) ++counts_.rotation_open_odometry_edges;
      keyframes_.push_back(std::move(k));
    }
    places_.add(step.descriptor);
    ++counts_.keyframes;
    const bool pausing =
        !loops().empty() && index <= last_loop_keyframe_ + options_.keyframes_between_loops;
    if (index % options_.search_every == 0 && !pausing) close_loops(index);
  }
  graph_.add_frame(keyframes_.size() - 1, step.offset);
  counts_.total_ms += step.ms + stopwatch.ms();
  return step.keyframe;
}

void LoopClosure2D::close_loops(std::size_t keyframe) {
  const Pose2 before = graph().pose(keyframe);
  if (!search_loops(keyframe)) return;
  optimize();
  if (moved_at_5m(before.inverse() * graph().pose(keyframe)) < options_.recheck_above) return;
  // The estimate just moved far: the keyframes before this one looked for loops where they were
  // wrongly placed, beyond the search window of the places they revisit. Look again.
  bool stale = false;
  const std::size_t first =
      keyframe > options_.recheck_keyframes ? keyframe - options_.recheck_keyframes : 0;
  for (std::size_t j = first; j < keyframe; ++j) stale = search_loops(j) || stale;
  if (stale) optimize();
}

bool LoopClosure2D::search_loops(std::size_t keyframe) {
  // A database match beyond the gate's reach is ruled out, unless a rotation-open step between
  // the two keyframes lets the gate turn the newer ones (agrees_turned_at_open_rotation).
  LoopCandidateReach reach;
  if (options_.registration_reach >= 0.0)
    reach = [&](std::size_t k) {
      const bool turnable =
          std::any_of(keyframes_.begin() + static_cast<std::ptrdiff_t>(k) + 1,
                      keyframes_.begin() + static_cast<std::ptrdiff_t>(keyframe) + 1,
                      [](const Keyframe& f) { return f.rotation_open; });
      return turnable ? std::numeric_limits<double>::infinity()
                      : correction_allowed(k, keyframe) + options_.registration_reach;
    };
  const LoopCandidateReach proximity = [&](std::size_t k) {
    return options_.candidates.proximity_radius * doubt_widening(k, keyframe);
  };
  const LoopCandidates found = find_loop_candidates(
      keyframe, options_.skip_recent, graph(), places_, options_.candidates, 0, reach, proximity);
  counts_.ruled_out_by_estimate += found.ruled_out;
  const Pose2& here = graph().pose(keyframe);
  const double max_error = loop_max_error();
  counts_.max_error_m = max_error;
  bool stale = false;
  // Each candidate's verification, prepared in order (the prepared references' cache is not
  // shared across threads), run side by side (each reads only its own reference, the shared
  // current scan and the graph as it stood), then judged in order as if run one by one: adding
  // a loop edge moves no pose before the next optimization.
  struct Tried {
    std::size_t keyframe;
    Pose2 estimated, initial;
    std::shared_ptr<const LoopReference2D> reference;
    LoopVerification2DOptions verification;
    LoopVerification2D result;
  };
  std::vector<Tried> tried;
  std::optional<LoopCurrent2D> current;  // for all of the keyframe's candidates
  for (const LoopCandidate& candidate : found.candidates) {
    const std::size_t k = candidate.keyframe;
    const bool linked = std::any_of(
        graph_.loops().begin(), graph_.loops().end(),
        [&](const Loop2D& l) { return l.from_keyframe == k && l.to_keyframe == keyframe; });
    if (linked) continue;
    ++counts_.candidates;
    std::vector<std::size_t> joined;
    if (options_.submap_keyframes > 0) {
      const std::size_t first = k > options_.submap_keyframes ? k - options_.submap_keyframes : 0;
      const std::size_t end = std::min(k + options_.submap_keyframes + 1, found.end);
      for (std::size_t j = first; j < end; ++j)
        if (j != k) joined.push_back(j);
    }
    const Pose2 estimated = graph().pose(k).inverse() * here;
    // The descriptor knows the yaw only: the translation is left to the search window.
    const Pose2 initial = candidate.by_descriptor ? pose2(0.0, 0.0, candidate.yaw) : estimated;
    // The prepared scans do not depend on the window.
    LoopVerification2DOptions verification = options_.verification;
    verification.search_window *= doubt_widening(k, keyframe);
    verification.max_error = max_error;
    if (!current) current.emplace(keyframes_[keyframe].points, options_.verification);
    tried.push_back({k, estimated, initial, prepared_reference(k, joined), verification, {}});
  }
  tbb::parallel_for(std::size_t{0}, tried.size(), [&](std::size_t i) {
    Tried& t = tried[i];
    t.result = verify_loop_2d(*current, *t.reference, t.initial, t.verification, t.estimated);
  });
  for (const Tried& t : tried) {
    const std::size_t k = t.keyframe;
    const Pose2& estimated = t.estimated;
    const LoopVerification2D& v = t.result;
    if (!v.accepted) {
      ++counts_.rejected_by_verification;
      continue;
    }
    const double allowed = correction_allowed(k, keyframe);
    if ((estimated.translation() - v.transform.translation()).norm() > allowed) {
      if (!agrees_turned_at_open_rotation(k, keyframe, graph().pose(k) * v.transform, allowed)) {
        ++counts_.rejected_by_estimate;
        continue;
      }
      ++counts_.turned_at_open_rotation;
    }
    ++counts_.verified;
    if (v.sliding) ++counts_.sliding;
    // How far the loop would move the keyframe's points at 5 m from the current estimate.
    if (moved_at_5m(estimated.inverse() * v.transform) >= options_.optimize_above) stale = true;
    last_loop_keyframe_ = std::max(last_loop_keyframe_, keyframe);
    Loop2D loop;
    loop.from_keyframe = k;
    loop.to_keyframe = keyframe;
    loop.from_scan = keyframes_[k].scan;
    loop.to_scan = keyframes_[keyframe].scan;
    loop.relative = v.transform;
    loop.paired_fraction = v.paired_fraction;
    loop.error = v.error;
    loop.sliding = v.sliding;
    loop.slide_direction = v.slide_direction;
    graph_.add_loop(loop, loop_information_2d(v, options_.loop_sigma_xy, options_.loop_sigma_theta,
                                              options_.hessian_loop_information,
                                              options_.sliding_information_kept));
  }
  return stale;
}

std::shared_ptr<const LoopReference2D> LoopClosure2D::prepared_reference(
    std::size_t keyframe, const std::vector<std::size_t>& joined) {
  PreparedReference wanted;
  wanted.keyframe = keyframe;
  for (const std::size_t j : joined)
    wanted.joined.emplace_back(j, graph().pose(keyframe).inverse() * graph().pose(j));
  const auto same = [&](const PreparedReference& p) {
    return p.keyframe == wanted.keyframe &&
           std::equal(p.joined.begin(), p.joined.end(), wanted.joined.begin(), wanted.joined.end(),
                      [](const auto& a, const auto& b) {
                        return a.first == b.first && a.second.matrix() == b.second.matrix();
                      });
  };
  const auto found = std::find_if(prepared_.begin(), prepared_.end(), same);
  if (found != prepared_.end()) {
    // The most recently used last.
    std::rotate(found, found + 1, prepared_.end());
    return prepared_.back().reference;
  }
  std::vector<PosedScan2D> neighbours;
  for (const auto& [j, pose] : wanted.joined) neighbours.push_back({&keyframes_[j].points, pose});
  wanted.reference = std::make_shared<const LoopReference2D>(keyframes_[keyframe].points,
                                                             neighbours, options_.verification);
  if (prepared_.size() >= kPreparedReferences) prepared_.erase(prepared_.begin());
  prepared_.push_back(std::move(wanted));
  return prepared_.back().reference;
}

double LoopClosure2D::loop_max_error() const {
  // The quieter quarter of the run's keyframe steps: turns (a rotating laser's scans distort) and
  // clutter raise the rest. Not before 20 keyframes: the first few (a start among clutter, or
  // turning) tell the sensor's floor badly.
  constexpr double kQuantile = 0.25;
  constexpr std::size_t kMinKeyframes = 20;
  const double fixed = options_.verification.max_error;
  if (!(options_.max_error_per_floor > 0.0)) return fixed;
  std::vector<double> errors;
  for (const Keyframe& k : keyframes_)
    if (k.pairing_error >= 0.0) errors.push_back(k.pairing_error);
  if (errors.size() < kMinKeyframes) return fixed;
  const auto at =
      errors.begin() + static_cast<std::ptrdiff_t>(kQuantile * static_cast<double>(errors.size()));
  std::nth_element(errors.begin(), at, errors.end());
  return std::max(fixed, options_.max_error_per_floor * *at);
}

double LoopClosure2D::doubt_widening(std::size_t older, std::size_t newer) const {
  const double weak =
      static_cast<double>(keyframes_[newer].weak_steps - keyframes_[older].weak_steps);
  return std::min(1.0 + options_.widening_per_weak_step * weak,
                  std::max(1.0, options_.max_doubt_widening));
}

double LoopClosure2D::correction_allowed(std::size_t older, std::size_t newer) const {
  return options_.max_correction +
         options_.max_correction_per_m * (keyframes_[newer].path - keyframes_[older].path);
}

bool LoopClosure2D::agrees_turned_at_open_rotation(std::size_t older, std::size_t newer,
                                                   const Pose2& implied, double allowed) const {
  const Pose2& here = graph().pose(newer);
  const double turn = pose2_angle(here.inverse() * implied);
  const Eigen::Rotation2Dd rotation(turn);
  for (std::size_t m = older + 1; m <= newer; ++m) {
    if (!keyframes_[m].rotation_open) continue;
    // Keyframe m's heading is open: it and every keyframe after it turn about its position.
    const Eigen::Vector2d pivot = graph().pose(m).translation();
    const Eigen::Vector2d turned = pivot + rotation * (here.translation() - pivot);
    if ((turned - implied.translation()).norm() <= allowed) return true;
  }
  return false;
}

double rotation_ambiguity_2d(const Scan2D& current, const Scan2D& previous,
                             const Pose2& measurement, double window, double at_least) {
  constexpr double kNear = 4.0 * M_PI / 180;
  constexpr double kFarFrom = 10.0 * M_PI / 180, kFarTo = 90.0 * M_PI / 180;
  const double fill_gap = Registration2DOptions{}.search_fill_gap;
  try {
    const double near = correlative_match(current, previous, measurement, window, kNear,
                                          kStepSpreadResolution, fill_gap)
                            .score;
    if (!(near > 0.0)) return 0.0;
    // A hair below the share asked for, so that a far fit at the threshold itself is still found
    // and the caller's comparison decides as without it.
    const double far_floor = std::clamp(at_least * near * (1.0 - 1e-6), 0.0, 1.0);
    double far = 0.0;
    for (const double side : {-1.0, 1.0}) {
      const Pose2 turned = pose2(measurement.translation().x(), measurement.translation().y(),
                                 pose2_angle(measurement) + side * 0.5 * (kFarFrom + kFarTo));
      far = std::max(far,
                     correlative_match(current, previous, turned, window, 0.5 * (kFarTo - kFarFrom),
                                       kStepSpreadResolution, fill_gap, std::max(far_floor, far))
                         .score);
    }
    return far / near;
  } catch (const Error&) {
    return 0.0;  // too few points to score: nothing to tell
  }
}

LoopKeyframes2D::OdometryInformation LoopKeyframes2D::odometry_information(
    const Scan2D& previous, const Scan2D& current, const Pose2& measurement) const {
  OdometryInformation out;
  out.information =
      diagonal_information<2>(options_.odometry_sigma_xy, options_.odometry_sigma_theta);
  if (!(options_.odometry_spread_window > 0.0)) return out;
  // A small angle window: the rotation is what scans determine best; it lets each translation
  // find its fit where the step's rotation is a little off.
  const CorrelativeSpread spread =
      correlative_spread(current, previous, measurement, options_.odometry_spread_window,
                         kStepSpreadAngle, kStepSpreadResolution,
                         Registration2DOptions{}.search_fill_gap, options_.odometry_spread_margin);
  if (spread.poses == 0 || !spread.second_moment.allFinite()) return out;
  out.information =
      spread_odometry_information(spread.second_moment, measurement, options_.odometry_sigma_xy,
                                  options_.odometry_sigma_theta, options_.odometry_spread_normal);
  out.open = widest_spread(spread).rms >= options_.open_step_spread;
  return out;
}

void LoopKeyframes2D::loosen_open_rotation(OdometryInformation& information, const Scan2D& previous,
                                           const Scan2D& current, const Pose2& measurement,
                                           bool weak_fit) const {
  if (!(options_.rotation_open_ratio > 0.0) ||
      (!weak_fit && std::abs(pose2_angle(measurement)) < options_.rotation_open_min_turn) ||
      rotation_ambiguity_2d(current, previous, measurement, 0.5, options_.rotation_open_ratio) <
          options_.rotation_open_ratio)
    return;
  information.rotation_open = true;
  information.information.row(2).setZero();
  information.information.col(2).setZero();
  information.information(2, 2) =
      1.0 / (options_.rotation_open_sigma_theta * options_.rotation_open_sigma_theta);
}

void LoopClosure2D::optimize() {
  counts_.outliers = graph_.optimize();
  ++counts_.optimizations;
}

void LoopClosure2D::finish() {
  const Stopwatch stopwatch;
  if (!loops().empty()) optimize();  // also the loops that agreed with the estimate when added
  counts_.total_ms += stopwatch.ms();
}

Pose2 LoopClosure2D::pose(std::size_t index) const {
  return graph_.pose(index);
}

std::vector<Pose2> LoopClosure2D::poses() const {
  return graph_.poses();
}

}  // namespace scanmatch
